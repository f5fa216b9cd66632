# Motion component and live pipeline contracts (issue 15), included from tests/CMakeLists.txt.
# view --animate on every machine kind against batch.
lbr_test(app_view_stream_test app_view_stream_test.cpp)
target_compile_definitions(app_view_stream_test PRIVATE LBR_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
