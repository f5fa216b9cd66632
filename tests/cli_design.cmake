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
