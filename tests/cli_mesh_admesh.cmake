# `lbrsim batch --stl` on curved work, checked by an independent tool (admesh, Debian package
# `admesh`; issue 13 item 6): no degenerate facets, no disconnected facets, nothing fixed,
# removed, added or reversed, no backwards edges, the expected number of parts.
# Inputs: LBRSIM, ADMESH, SRC, OUT.
file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")

function(check_part name parts)
  execute_process(COMMAND "${LBRSIM}" batch --quiet --out "${OUT}/${name}" --stl "${OUT}/${name}.stl" ${ARGN}
                  WORKING_DIRECTORY "${SRC}" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${name}: lbrsim batch failed (${rc}): ${out} ${err}")
  endif()
  execute_process(COMMAND "${ADMESH}" "${OUT}/${name}.stl" RESULT_VARIABLE rc OUTPUT_VARIABLE rep ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${name}: admesh failed (${rc}): ${err}")
  endif()
  string(REGEX MATCH "Number of facets +: +([0-9]+)" m "${rep}")
  if(NOT m OR CMAKE_MATCH_1 LESS 1000)
    message(FATAL_ERROR "${name}: no facet count in admesh's report:\n${rep}")
  endif()
  set(facets ${CMAKE_MATCH_1})
  # Original column of the facet status, then the processing statistics.
  foreach(key "Facets with 1 disconnected edge" "Facets with 2 disconnected edges" "Facets with 3 disconnected edges"
              "Degenerate facets" "Edges fixed" "Facets removed" "Facets added" "Facets reversed" "Backwards edges"
              "Normals fixed")
    string(REGEX MATCH "${key} +: +([0-9]+)" m "${rep}")
    if(NOT m)
      message(FATAL_ERROR "${name}: '${key}' missing from admesh's report:\n${rep}")
    endif()
    if(NOT CMAKE_MATCH_1 EQUAL 0)
      message(FATAL_ERROR "${name}: admesh: ${key} = ${CMAKE_MATCH_1} (expected 0)\n${rep}")
    endif()
  endforeach()
  string(REGEX MATCH "Number of parts +: +([0-9]+)" m "${rep}")
  if(NOT CMAKE_MATCH_1 EQUAL ${parts})
    message(FATAL_ERROR "${name}: admesh: ${CMAKE_MATCH_1} parts (expected ${parts})\n${rep}")
  endif()
  message(STATUS "${name}: ${facets} facets, ${parts} part(s), admesh clean")
endfunction()

check_part(ball-groove 1 --program tests/data/mesh/ball-groove.ngc)
# The helical bore's sampled stream: admesh-clean since the kernel drops the slivers of its
# rounding (docs/mesh.md §6); mesh_clean_test still counts its four-use edges apart.
check_part(helical-bore-sampled 1 --program tests/data/mesh/helical-bore.ngc --tool 3:flat:8 --sampled)
check_part(ball-raster 1 --program tests/data/mesh/ball-raster.ngc)
# Issue 13's helix workload in both modes: admesh-clean since cap rings start at their least
# vertex (mesh/src/plane.cpp, canonical_order(); before: 8 facets reversed in --sampled).
check_part(helix 1 --program bench/programs/helix.ngc)
check_part(helix-sampled 1 --program bench/programs/helix.ngc --sampled)
check_part(cam-pocket-blended-sampled 1 --program config/programs/cam-pocket.ngc --sampled)
# cam-pocket's sampled stream with exact stop at every block (G61.1 after the leading %): the
# blended stream has a fifth self-touching cap that admesh reports (docs/mesh.md §6).
file(READ "${SRC}/config/programs/cam-pocket.ngc" pocket)
string(REGEX REPLACE "^%\n" "%\nG61.1\n" pocket "${pocket}")
file(WRITE "${OUT}/cam-pocket-exact-stop.ngc" "${pocket}")
check_part(cam-pocket-sampled 1 --program "${OUT}/cam-pocket-exact-stop.ngc" --sampled)
check_part(high 1 --program bench/programs/high.ngc)
