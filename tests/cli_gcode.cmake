# lbrsim with G-code: batch (interpreted and --sampled), emulate (CSV), error reporting, and
# --interpreter rs274 where LinuxCNC's rs274 is installed. A small program keeps this fast.
file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")
# A 20 mm square pocket 2 mm deep with an arc corner, and a drilled hole; the default profile
# (stock 100 x 80 x 30, G54 origin 250 mm below machine home).
file(WRITE "${OUT}/part.ngc" "%
(small part)
G21 G90 G17 G94
G28 G91 Z0
G90
T1 M6
G43 H1 G0 X30 Y30 Z5
G1 Z-2 F400
G1 X50 F1200
G1 Y50
G3 X40 Y60 R10
G1 X30
G1 Y30
G0 Z25
T3 M6
G43 H3 G0 X70 Y20 Z10
G98 G81 Z-6 R2 F200
G80
M30
%
")
set(common --quiet --level-spacing 0.5 --regions 2x2 --program "${OUT}/part.ngc")
execute_process(COMMAND "${LBRSIM}" batch ${common} --out "${OUT}/a" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "lbrsim batch part.ngc failed (${rc}): ${out} ${err}")
endif()
file(READ "${OUT}/a/metrics.json" m)
string(JSON removed GET "${m}" removed_volume_mm3)
string(JSON time GET "${m}" machining_time_s)
# Pocket: a 10 mm tool along a 20 x 20 square with one R10 corner, 2 mm deep (~1950 mm3 by hand),
# plus the 8 mm drill to -6 (~270 mm3) — at a level spacing of 0.5 mm.
if(removed LESS 1800 OR removed GREATER 2500)
  message(FATAL_ERROR "removed volume ${removed} mm3 outside [1800, 2500]")
endif()
if(time LESS 5 OR time GREATER 60)
  message(FATAL_ERROR "machining time ${time} s outside [5, 60]")
endif()

execute_process(COMMAND "${LBRSIM}" batch ${common} --sampled --out "${OUT}/b" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "lbrsim batch --sampled failed (${rc}): ${out} ${err}")
endif()
file(READ "${OUT}/b/metrics.json" m)
string(JSON removed_s GET "${m}" removed_volume_mm3)
string(JSON time_s GET "${m}" machining_time_s)
if(NOT time_s EQUAL time)
  message(FATAL_ERROR "--sampled machining time ${time_s} differs from ${time}")
endif()
# The sampled stream covers the same path: the same volume to within 2 mm3 (integer parts).
string(REGEX REPLACE "\\..*" "" ri "${removed}")
string(REGEX REPLACE "\\..*" "" rsi "${removed_s}")
math(EXPR d "${ri} - ${rsi}")
if(d GREATER 2 OR d LESS -2)
  message(FATAL_ERROR "--sampled removed ${removed_s} mm3, interpreted ${removed} mm3")
endif()

execute_process(COMMAND "${LBRSIM}" emulate "${OUT}/part.ngc" --period 4ms --out "${OUT}/s.csv"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "^([0-9]+) samples every 4 ms \\| machining ([0-9.]+) s")
  message(FATAL_ERROR "lbrsim emulate failed (${rc}): ${out} ${err}")
endif()
set(count ${CMAKE_MATCH_1})
file(STRINGS "${OUT}/s.csv" rows)
list(LENGTH rows nrows)
math(EXPR nsamples "${nrows} - 1")
if(NOT nsamples EQUAL count)
  message(FATAL_ERROR "samples.csv has ${nsamples} rows, emulate reported ${count}")
endif()
list(GET rows 0 header)
if(NOT header STREQUAL "seq,t_s,tool,x_mm,y_mm,z_mm,a_deg,b_deg,c_deg")
  message(FATAL_ERROR "unexpected CSV header: ${header}")
endif()
list(GET rows 1 first)
if(NOT first MATCHES "^0,0.004000,")
  message(FATAL_ERROR "unexpected first sample: ${first}")
endif()

# Errors name file, line and word.
file(WRITE "${OUT}/bad.ngc" "G21 G90\nG0 X1\nG41 D1 X2\n")
execute_process(COMMAND "${LBRSIM}" batch --quiet --program "${OUT}/bad.ngc" --out "${OUT}/c" RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "bad.ngc:3: the cutter compensation entry move \\(1 mm in the plane\\) is not longer than the tool radius \\(5 mm\\)")
  message(FATAL_ERROR "bad G-code not reported as expected (rc ${rc}): ${err}")
endif()

# --start-tool: a program without M6 on a machine whose spindle already holds tool 1.
file(WRITE "${OUT}/notool.ngc" "G21 G90 G43\nG0 X30 Y30 Z5\nG1 Z-2 F400\nG1 X50\nM2\n")
execute_process(COMMAND "${LBRSIM}" batch --level-spacing 0.5 --program "${OUT}/notool.ngc" --out "${OUT}/t0"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
file(READ "${OUT}/t0/metrics.json" m)
string(JSON removed0 GET "${m}" removed_volume_mm3)
if(NOT rc EQUAL 0 OR NOT removed0 EQUAL 0 OR NOT "${out}${err}" MATCHES "notool.ngc:3: 2 feed moves run with no tool loaded.*--start-tool N")
  message(FATAL_ERROR "tool-0 program: rc ${rc}, removed ${removed0}, expected the --start-tool warning: ${out} ${err}")
endif()
execute_process(COMMAND "${LBRSIM}" batch --quiet --level-spacing 0.5 --start-tool 1 --program "${OUT}/notool.ngc"
                --out "${OUT}/t1" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
file(READ "${OUT}/t1/metrics.json" m)
string(JSON removed1 GET "${m}" removed_volume_mm3)
# A 10 mm tool 2 mm deep along 20 mm plus the plunge: ~ 20 x 10 x 2 + pi 25 x 2 = 557 mm3.
if(NOT rc EQUAL 0 OR removed1 LESS 500 OR removed1 GREATER 620 OR "${out}${err}" MATCHES "no tool loaded")
  message(FATAL_ERROR "--start-tool 1: rc ${rc}, removed ${removed1} mm3 outside [500, 620]: ${out} ${err}")
endif()

find_program(RS274 rs274)
if(RS274)
  execute_process(COMMAND "${LBRSIM}" emulate "${OUT}/part.ngc" --interpreter rs274 --period 4ms --out "${OUT}/r.csv"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "lbrsim emulate --interpreter rs274 failed (${rc}): ${out} ${err}")
  endif()
  file(READ "${OUT}/s.csv" mine)
  file(READ "${OUT}/r.csv" theirs)
  if(NOT mine STREQUAL theirs)
    message(FATAL_ERROR "rs274 and the built-in interpreter give different sample streams")
  endif()
else()
  message(STATUS "rs274 not installed: --interpreter rs274 not exercised here")
endif()
