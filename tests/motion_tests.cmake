# Motion component and live pipeline contracts (issue 15), included from tests/CMakeLists.txt.
# view --animate on every machine kind against batch.
lbr_test(app_view_stream_test app_view_stream_test.cpp)
target_compile_definitions(app_view_stream_test PRIVATE LBR_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
# Real-time contracts: allocations on the HAL path, the motion stream and a geometry tick
# (white-box: the live pipeline's private headers in app/src/live/).
lbr_test(app_live_alloc_test app_live_alloc_test.cpp alloc_counter.cpp)
target_include_directories(app_live_alloc_test PRIVATE ${PROJECT_SOURCE_DIR}/app/src)
# Live collision checks on the geometry thread (issue 16, white-box like the one above).
lbr_test(app_live_checks_test app_live_checks_test.cpp alloc_counter.cpp)
target_include_directories(app_live_checks_test PRIVATE ${PROJECT_SOURCE_DIR}/app/src)
# Emulator blending against exact stop through the kernel (docs/nc-frontend.md#planner).
lbr_test(app_emulator_blend_test app_emulator_blend_test.cpp)
target_compile_definitions(app_emulator_blend_test PRIVATE LBR_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
# The motion stream's merged runs, 5-axis included (geom::pose_deviation_mm).
lbr_test(motion_sample_stream_test motion_sample_stream_test.cpp)
