# lbrsim's rendering from the command line (issue 6), run by ctest with -DLBRSIM=... -DOUT=...
#  1. `batch --png` under xvfb-run writes a PNG of the requested size;
#  2. without any display, `batch --png` fails cleanly with a message suggesting xvfb-run;
#  3. `view --hidden --frames N --screenshot-every M` runs the render thread headless;
#  4. `run` (live pipeline) renders without changing its result.
file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")

function(png_size file out_w out_h)
  file(READ "${file}" hex LIMIT 24 HEX)
  string(SUBSTRING "${hex}" 0 16 sig)
  if(NOT sig STREQUAL "89504e470d0a1a0a")
    message(FATAL_ERROR "${file} is not a PNG (signature ${sig})")
  endif()
  string(SUBSTRING "${hex}" 32 8 w)
  string(SUBSTRING "${hex}" 40 8 h)
  math(EXPR w "0x${w}")
  math(EXPR h "0x${h}")
  set(${out_w} ${w} PARENT_SCOPE)
  set(${out_h} ${h} PARENT_SCOPE)
endfunction()

execute_process(COMMAND xvfb-run -a "${LBRSIM}" batch --quiet --out "${OUT}/run" --png "${OUT}/top.png" --view top
                        --color heat --size 320x240
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "batch --png failed (${rc}): ${out} ${err}")
endif()
png_size("${OUT}/top.png" w h)
if(NOT w EQUAL 320 OR NOT h EQUAL 240)
  message(FATAL_ERROR "top.png is ${w}x${h}, expected 320x240")
endif()

execute_process(COMMAND "${CMAKE_COMMAND}" -E env --unset=DISPLAY --unset=WAYLAND_DISPLAY
                        "${LBRSIM}" batch --quiet --out "${OUT}/run2" --png "${OUT}/none.png"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "batch --png without a display succeeded")
endif()
if(NOT rc EQUAL 1 OR NOT err MATCHES "xvfb-run" OR NOT err MATCHES "DISPLAY")
  message(FATAL_ERROR "batch --png without a display: expected exit 1 and a hint to use xvfb-run, got ${rc}: ${err}")
endif()
if(EXISTS "${OUT}/none.png")
  message(FATAL_ERROR "none.png was written without a display")
endif()

execute_process(COMMAND xvfb-run -a "${LBRSIM}" view --quiet --hidden --frames 10 --screenshot-every 5
                        --screenshot-prefix "${OUT}/shot-" --size 200x150 --color regions
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "frames 10 ")
  message(FATAL_ERROR "view --hidden failed (${rc}): ${out} ${err}")
endif()
foreach(f shot-000000.png shot-000005.png)
  if(NOT EXISTS "${OUT}/${f}")
    message(FATAL_ERROR "view --hidden did not write ${f}")
  endif()
  png_size("${OUT}/${f}" w h)
  if(NOT w EQUAL 200 OR NOT h EQUAL 150)
    message(FATAL_ERROR "${f} is ${w}x${h}, expected 200x150")
  endif()
endforeach()

# 4. `lbrsim run` with rendering: the live pipeline's result is the same with and without
#    the render thread (as-fast-as-possible emulator source: deterministic batching), and
#    screenshots are written; without a display --screenshot-every fails with the hint.
set(prog "${SRC}/tests/data/live-short.moves")
execute_process(COMMAND "${LBRSIM}" run --source "emulator:${prog}" --speed 0 --quiet --no-window --out "${OUT}/live1"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out1 ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "run --no-window failed (${rc}): ${out1} ${err}")
endif()
execute_process(COMMAND xvfb-run -a "${LBRSIM}" run --source "emulator:${prog}" --speed 0 --quiet --hidden
                        --screenshot-every 1 --screenshot-prefix "${OUT}/live-" --size 160x120 --out "${OUT}/live2"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out2 ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "run --hidden --screenshot-every failed (${rc}): ${out2} ${err}")
endif()
string(REGEX MATCH "removed [0-9.]+ mm3" v1 "${out1}")
string(REGEX MATCH "removed [0-9.]+ mm3" v2 "${out2}")
if(v1 STREQUAL "" OR NOT v1 STREQUAL v2)
  message(FATAL_ERROR "run with rendering changed the result: '${v1}' vs '${v2}'")
endif()
if(NOT EXISTS "${OUT}/live-000000.png")
  message(FATAL_ERROR "run --screenshot-every 1 wrote no screenshot")
endif()
png_size("${OUT}/live-000000.png" w h)
if(NOT w EQUAL 160 OR NOT h EQUAL 120)
  message(FATAL_ERROR "live-000000.png is ${w}x${h}, expected 160x120")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" -E env --unset=DISPLAY --unset=WAYLAND_DISPLAY
                        "${LBRSIM}" run --source "emulator:${prog}" --speed 0 --quiet --screenshot-every 5 --out "${OUT}/live3"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 1 OR NOT err MATCHES "xvfb-run")
  message(FATAL_ERROR "run --screenshot-every without a display: expected exit 1 and the xvfb-run hint, got ${rc}: ${err}")
endif()
