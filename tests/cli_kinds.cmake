# lbrsim batch on every machine kind's bundled profile and example program (issue 7), with
# the removed volume checked against the hand count in each program's header:
#  - lathe-shaft.ngc: 26851.8 mm3 less the nose-radius fillets (~12 mm3);
#  - lathe-c-parts.ngc: face 502.7 + hexagon 3817.7 + cross hole 2003.0 + flat 3233.1 mm3
#    (cross hole and flat as sampled at Δ = 0.2 mm);
#  - mill5-tilted.ngc: face 3600 + tilted slot 28.454 mm2 x 60 mm = 5307.3 mm3;
#  - twin-turret-lathe.toml (two channels): face 502.7 + D30 over 19.6 mm 10776.3 + two
#    grooves 3298.7 = 14577.7 mm3 less the 0.8 nose fillet (~13 mm3), also with --sampled.
# Then the emulator path (lbrsim emulate) on lathe-c, and profile errors with file:line.
file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")

function(check_volume name lo hi)
  execute_process(COMMAND "${LBRSIM}" batch --quiet ${ARGN} --out "${OUT}/${name}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${name}: lbrsim batch failed (${rc}): ${out} ${err}")
  endif()
  file(READ "${OUT}/${name}/metrics.json" metrics)
  string(JSON removed GET "${metrics}" removed_volume_mm3)
  string(JSON factor GET "${metrics}" factor)
  if(removed LESS ${lo} OR removed GREATER ${hi})
    message(FATAL_ERROR "${name}: removed volume ${removed} mm3 outside [${lo}, ${hi}]")
  endif()
  message(STATUS "${name}: removed ${removed} mm3, batch factor ${factor}")
endfunction()

set(P ${SRC}/config/profiles)
set(G ${SRC}/config/programs)
check_volume(lathe 26825 26850 --profile ${P}/lathe.toml --program ${G}/lathe-shaft.ngc)
check_volume(lathe-c 9550 9562 --profile ${P}/lathe-c.toml --program ${G}/lathe-c-parts.ngc)
check_volume(mill5 5304 5310 --profile ${P}/mill5-ac.toml --program ${G}/mill5-tilted.ngc)
check_volume(twin 14558 14572 --profile ${P}/twin-turret-lathe.toml)
check_volume(twin-sampled 14558 14572 --sampled --profile ${P}/twin-turret-lathe.toml)

# Emulator path: the C axis reaches the samples.
execute_process(COMMAND "${LBRSIM}" emulate ${G}/lathe-c-parts.ngc --profile ${P}/lathe-c.toml --out "${OUT}/lc.csv"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "lbrsim emulate lathe-c failed (${rc}): ${out} ${err}")
endif()

# Profiles: every bundled one checks; a kind-specific key on the wrong kind names file:line.
foreach(f lathe lathe-c mill5-ac twin-turret-lathe)
  execute_process(COMMAND "${LBRSIM}" profile ${P}/${f}.toml RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "profile ${f}: ${out} ${err}")
  endif()
endforeach()
file(WRITE "${OUT}/bad.toml" "[machine]\nkind = \"mill3\"\nrotary = \"table-ac\"\n[stock]\nshape = \"box\"\nmin_mm = [0, 0, 0]\nmax_mm = [1, 1, 1]\n")
execute_process(COMMAND "${LBRSIM}" profile "${OUT}/bad.toml" RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "bad.toml:3: machine.rotary: only for machine kind mill5")
  message(FATAL_ERROR "bad profile not reported as expected (rc ${rc}): ${err}")
endif()

# Live path: `lbrsim run` with the emulator source maps every sample through the same
# kinematics (here the A30 swing of the trunnion table) and removes the same volume.
execute_process(COMMAND "${LBRSIM}" run --quiet --source emulator:${G}/mill5-tilted.ngc --speed 0
                        --profile ${P}/mill5-ac.toml --out "${OUT}/run-mill5"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "lbrsim run mill5 failed (${rc}): ${out} ${err}")
endif()
file(READ "${OUT}/run-mill5/metrics.json" metrics)
string(JSON removed GET "${metrics}" removed_volume_mm3)
if(removed LESS 5304 OR removed GREATER 5310)
  message(FATAL_ERROR "lbrsim run mill5: removed volume ${removed} mm3 outside [5304, 5310]")
endif()
