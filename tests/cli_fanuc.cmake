# lbrsim batch with a Fanuc-dialect program (docs/nc-frontend.md#fanuc-dialect): the bundled
# config/programs/fanuc-flange.nc (G65 macro pocket, WHILE bolt circle, M98 L3 slot) removes
# exactly the volume of its RS274/NGC twin fanuc-flange.ngc, selected by a profile with
# [nc] dialect = "fanuc" and by --dialect fanuc; the NGC dialect and rs274 refuse it.
file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")
file(READ "${SRC}/config/profiles/default-mill3.toml" profile)
file(WRITE "${OUT}/fanuc.toml" "${profile}\n[nc]\ndialect = \"fanuc\"\n")
set(common --quiet --level-spacing 0.25 --regions 2x2)

function(removed_volume name)
  execute_process(COMMAND "${LBRSIM}" batch ${common} ${ARGN} --out "${OUT}/${name}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "lbrsim batch ${ARGN} failed (${rc}): ${out} ${err}")
  endif()
  file(READ "${OUT}/${name}/metrics.json" m)
  string(JSON v GET "${m}" removed_volume_mm3)
  set(${name} "${v}" PARENT_SCOPE)
endfunction()

removed_volume(ngc --program "${SRC}/config/programs/fanuc-flange.ngc")
removed_volume(fanuc_profile --profile "${OUT}/fanuc.toml" --program "${SRC}/config/programs/fanuc-flange.nc")
removed_volume(fanuc_cli --dialect fanuc --program "${SRC}/config/programs/fanuc-flange.nc")
# Pocket 30 mm x 6 mm (4241 mm3), eight 8 mm drills 8 mm deep (~2570 mm3), slot 90 x 10 mm
# with round ends x 3 mm (~2636 mm3): ~9447 mm3 by hand, a little less in levels.
if(ngc LESS 9000 OR ngc GREATER 9600)
  message(FATAL_ERROR "fanuc-flange.ngc removed ${ngc} mm3, expected about 9447 mm3")
endif()
if(NOT fanuc_profile STREQUAL ngc OR NOT fanuc_cli STREQUAL ngc)
  message(FATAL_ERROR "fanuc-flange.nc removed ${fanuc_profile} mm3 (profile) / ${fanuc_cli} mm3 (--dialect), "
                      "its NGC twin ${ngc} mm3")
endif()

execute_process(COMMAND "${LBRSIM}" batch ${common} --program "${SRC}/config/programs/fanuc-flange.nc" --out "${OUT}/x"
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(rc EQUAL 0 OR NOT err MATCHES "fanuc-flange.nc:2: O-word 'O1000' without a keyword.*--dialect fanuc")
  message(FATAL_ERROR "the rs274ngc dialect should refuse fanuc-flange.nc at line 2 (${rc}): ${err}")
endif()
execute_process(COMMAND "${LBRSIM}" batch ${common} --interpreter rs274 --dialect fanuc
                        --program "${SRC}/config/programs/fanuc-flange.nc" --out "${OUT}/y"
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(rc EQUAL 0 OR NOT err MATCHES "built-in interpreter only")
  message(FATAL_ERROR "--interpreter rs274 --dialect fanuc should be refused (${rc}): ${err}")
endif()
