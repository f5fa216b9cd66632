# `lbrsim batch --design`: a file that is not an STL stops the run before it starts, with
# exit status 1 and the reason; an ASCII STL of the whole stock (a design nothing should be
# cut from) against the demo reports the demo's removed volume as gouge, in metrics.json and
# deviation.csv.
file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")
execute_process(COMMAND "${LBRSIM}" batch --quiet --out "${OUT}/bad" --design "${SRC}/config/programs/cam-pocket.ngc"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 1 OR NOT err MATCHES "cam-pocket.ngc: expected an STL file")
  message(FATAL_ERROR "--design with a G-code file: exit ${rc} (expected 1): ${out} ${err}")
endif()
# The default stock X0..100 Y0..80 Z-30..0 as 12 triangles.
set(v000 "0 0 -30")
set(v100 "100 0 -30")
set(v010 "0 80 -30")
set(v110 "100 80 -30")
set(v001 "0 0 0")
set(v101 "100 0 0")
set(v011 "0 80 0")
set(v111 "100 80 0")
set(stl "solid stock\n")
foreach(t "000 010 110" "000 110 100" "001 101 111" "001 111 011" "000 100 101" "000 101 001"
          "010 011 111" "010 111 110" "000 001 011" "000 011 010" "100 110 111" "100 111 101")
  string(REPLACE " " ";" t "${t}")
  string(APPEND stl "facet normal 0 0 0\nouter loop\n")
  foreach(k IN LISTS t)
    string(APPEND stl "vertex ${v${k}}\n")
  endforeach()
  string(APPEND stl "endloop\nendfacet\n")
endforeach()
string(APPEND stl "endsolid stock\n")
file(WRITE "${OUT}/stock.stl" "${stl}")
execute_process(COMMAND "${LBRSIM}" batch --quiet --out "${OUT}/run" --design "${OUT}/stock.stl"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "design: gouge")
  message(FATAL_ERROR "--design stock.stl: exit ${rc}: ${out} ${err}")
endif()
file(READ "${OUT}/run/metrics.json" m)
string(JSON removed GET "${m}" removed_volume_mm3)
string(JSON gouge GET "${m}" design_gouge_mm3)
string(JSON excess GET "${m}" design_excess_mm3)
# Everything the demo removed lay inside this design: gouge = removed volume (to the
# integer mm3), no excess.
string(REGEX MATCH "^[0-9]+" removed_mm3 "${removed}")
string(REGEX MATCH "^[0-9]+" gouge_mm3 "${gouge}")
if(NOT removed_mm3 EQUAL gouge_mm3 OR excess GREATER 0.001 OR NOT EXISTS "${OUT}/run/deviation.csv")
  message(FATAL_ERROR "--design stock.stl: gouge ${gouge} mm3 (expected ${removed}), excess ${excess} mm3")
endif()
# The demo cuts that design deeply: one design-gouge error, so --fail-on error exits 3.
execute_process(COMMAND "${LBRSIM}" batch --quiet --out "${OUT}/fail" --design "${OUT}/stock.stl" --fail-on error
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 3 OR NOT "${out}${err}" MATCHES "checks: 1 error,.*design-gouge")
  message(FATAL_ERROR "--design stock.stl --fail-on error: exit ${rc} (expected 3): ${out} ${err}")
endif()

# `lbrsim run --design` (docs/verification.md#live-design): the emulated demo compared when
# the run ends, by batch's comparison: gouge = the run's removed volume (to the integer mm3),
# within 1 % of batch's, no excess, deviation.csv and a design-gouge event in events.csv.
execute_process(COMMAND "${LBRSIM}" run --source emulator:demo --speed 0 --no-window --quiet --out "${OUT}/live"
                        --design "${OUT}/stock.stl"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "design: gouge [0-9.]+ mm3")
  message(FATAL_ERROR "run --design stock.stl: exit ${rc}: ${out} ${err}")
endif()
file(READ "${OUT}/live/metrics.json" m)
string(JSON live_removed GET "${m}" removed_volume_mm3)
string(JSON live_gouge GET "${m}" design_gouge_mm3)
string(JSON live_excess GET "${m}" design_excess_mm3)
string(REGEX MATCH "^[0-9]+" live_removed_mm3 "${live_removed}")
string(REGEX MATCH "^[0-9]+" live_gouge_mm3 "${live_gouge}")
math(EXPR diff "${live_gouge_mm3} - ${gouge_mm3}")
if(diff LESS 0)
  math(EXPR diff "0 - ${diff}")
endif()
math(EXPR diff100 "${diff} * 100")
file(READ "${OUT}/live/events.csv" events)
if(NOT live_removed_mm3 EQUAL live_gouge_mm3 OR live_excess GREATER 0.001 OR diff100 GREATER gouge_mm3
   OR NOT EXISTS "${OUT}/live/deviation.csv" OR NOT events MATCHES "design-gouge")
  message(FATAL_ERROR "run --design stock.stl: gouge ${live_gouge} mm3 (removed ${live_removed}, batch ${gouge}), "
                      "excess ${live_excess} mm3: ${events}")
endif()
# --color deviation without a design model is a usage error, for run and view alike.
execute_process(COMMAND "${LBRSIM}" run --no-window --color deviation RESULT_VARIABLE rc_run ERROR_VARIABLE err_run)
execute_process(COMMAND "${LBRSIM}" view --color deviation RESULT_VARIABLE rc_view ERROR_VARIABLE err_view)
if(NOT rc_run EQUAL 1 OR NOT err_run MATCHES "--color deviation needs --design" OR NOT rc_view EQUAL 1
   OR NOT err_view MATCHES "--color deviation needs --design")
  message(FATAL_ERROR "--color deviation without --design: run exit ${rc_run}, view exit ${rc_view} (expected 1): "
                      "${err_run} ${err_view}")
endif()
