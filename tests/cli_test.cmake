# Runs the drapegen program end to end on a small drape and checks its outputs and its errors.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

include(${CMAKE_CURRENT_LIST_DIR}/expect_error.cmake)
include(${CMAKE_CURRENT_LIST_DIR}/json_number.cmake)
# expect_failure(EXIT NEEDLE COMMAND ARGS...): `drapegen COMMAND ARGS...` fails with a one-line error of COMMAND's
# ("drapegen COMMAND: error: ...") that says NEEDLE.
function(expect_failure code_expected needle command)
  expect_drapegen_error(CODE ${code_expected} SUB ${command} SAYS "${needle}" ARGS ${command} ${ARGN})
endfunction()

execute_process(COMMAND ${DRAPEGEN} simulate --alpha 20000,15000,10000 --beta -40000,-30000,-20000 --resolution 25
                        --init sine --seed 3 --drift 2 --out ${WORK}/drape.ply --json
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "simulate failed (${code}): ${out} ${err}")
endif()
string(JSON outcome GET "${out}" outcome)
json_number(dc "${out}" drape_coefficient)
json_number(si "${out}" self_intersections)
if(NOT outcome STREQUAL "converged")
  message(FATAL_ERROR "drape did not converge: ${out}")
endif()
if(dc LESS_EQUAL 0.1 OR dc GREATER_EQUAL 1.0)
  message(FATAL_ERROR "implausible drape coefficient ${dc}")
endif()
if(NOT EXISTS ${WORK}/drape.ply)
  message(FATAL_ERROR "no mesh written")
endif()

# The drape of one sample is a valid initial state of another.
execute_process(COMMAND ${DRAPEGEN} simulate --alpha 30000 --resolution 25 --init mesh:${WORK}/drape.ply --json
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "simulate from a mesh failed (${code}): ${out} ${err}")
endif()

expect_failure(1 "alpha (warp, bias, weft) must be positive" simulate --alpha -5,1,1)
expect_failure(1 "--beta: 'nan' is not a finite number" simulate --alpha 1000 --beta nan)
expect_failure(1 "unknown initial state 'wavy'" simulate --alpha 1000 --init wavy)
expect_failure(1 "--mesh: hexagonal not in" simulate --alpha 1000 --mesh hexagonal)
expect_failure(1 "--mesh excludes --structured" simulate --alpha 1000 --mesh uniform --structured)
expect_failure(1 "--model: foo not in" simulate --alpha 1000 --model foo)
expect_failure(1 "--alpha is required" simulate)
# (No command recognised: "drapegen: error: ...".)
expect_drapegen_error(CODE 1 SAYS "unknown command 'frobnicate'; the commands: simulate" ARGS frobnicate)
expect_failure(1 "--resolution must be between 5 and 1000" simulate --alpha 1000 --resolution 2)
# Below 5: no vertex on the platform top at all.
expect_failure(1 "--resolution must be between 5 and 1000" simulate --alpha 1000 --resolution 4)
# The summary is an output too: a full disk (/dev/full) under the standard output is exit 3, not a silent 0.
if(EXISTS /dev/full)
  execute_process(COMMAND ${DRAPEGEN} sample --n 3 --seed 1 --out ${WORK}/full_params.csv --json
                  OUTPUT_FILE /dev/full RESULT_VARIABLE code ERROR_VARIABLE err)
  if(NOT code EQUAL 3 OR NOT err MATCHES "cannot write the standard output")
    message(FATAL_ERROR "a summary written to a full disk: exit ${code}, ${err}")
  endif()
endif()
expect_failure(1 "--coarse-start must be 0 (off) or at least 3" simulate --alpha 1000 --coarse-start 2)
expect_failure(1 "--lagged-updates must be 1..1000" simulate --alpha 1000 --lagged-updates 0)
expect_failure(1 "--load-steps must be 1..100" simulate --alpha 1000 --load-steps 0)
expect_failure(1 "'${WORK}/missing.ply': cannot open" simulate --alpha 1000 --init mesh:${WORK}/missing.ply)
expect_failure(1 "has 625 vertices; the specimen has 900" simulate --alpha 1000 --resolution 30
               --init mesh:${WORK}/drape.ply)
expect_failure(3 "cannot write '/nonexistent-dir/drape.ply'" simulate --alpha 1000 --resolution 5
               --out /nonexistent-dir/drape.ply)
# A directory where a file goes: refused before the work, not after it.
file(MAKE_DIRECTORY ${WORK}/a-directory)
expect_failure(3 "cannot write '${WORK}/a-directory': it is a directory" simulate --alpha 1000 --resolution 5
               --out ${WORK}/a-directory)
expect_failure(3 "cannot write '${WORK}/a-directory': it is a directory" sample --n 10 --out ${WORK}/p.csv
               --recipes ${WORK}/a-directory)
expect_failure(1 "model file '${WORK}/a-directory' is a directory" sample --n 10 --model ${WORK}/a-directory)
expect_failure(1 "--seed: '-1' is not a seed" simulate --alpha 1000 --resolution 5 --seed -1)
expect_failure(1 "--seed: '18446744073709551616' is not a seed" simulate --alpha 1000 --resolution 5
               --seed 18446744073709551616)
expect_failure(1 "--tolerance must be positive" simulate --alpha 1000 --tolerance 0)
expect_failure(1 "--drift: expected MM (>= 0) or DX,DY in millimetres, got '1,x'" simulate --alpha 1000 --drift 1,x)
expect_failure(1 "--band: need 0 < LOW <= 1 <= HIGH" simulate --alpha 1000 --band 1.2,1.3)
expect_failure(1 "--band: expected LOW,HIGH" simulate --alpha 1000 --band 0.99x,1.01)
# (A third value was parsed and dropped.)
expect_failure(1 "--band: expected LOW,HIGH" simulate --alpha 1000 --band 0.99,1.05,7)
expect_failure(1 "--resolution must be between 5 and 1000" simulate --alpha 1000 --resolution 5000)
expect_failure(1 "no vertex of the initial state rests on the platform top" simulate --alpha 1000 --resolution 10
               --drift 1000)
expect_failure(1 "no vertex of the initial state rests on the platform top" simulate --alpha 1000 --resolution 10
               --drift 1e300)
expect_failure(1 "--density must be between 1 and 100000" simulate --alpha 1000 --density 1e-320)
expect_failure(1 "--segments must be between 4 and 2000" cantilever --length 0.1 --alpha 1000 --segments 100000)
expect_failure(1 "--length must be positive and at most 10" cantilever --length -1 --alpha 1000)
# (It ran for minutes in the Newton solve.)
expect_failure(1 "--length must be positive and at most 10" cantilever --length 1e6 --alpha 1000)
expect_failure(1 "--alpha must be positive" cantilever --length 0.1 --alpha 0)

# The program runs on the BLAS kernels the CPU supports (blas_kernels.hpp): never on OpenBLAS's generic Prescott
# kernels where the CPU has AVX2 and FMA, unless the user asked for them. Only for an x86-64 OpenBLAS that chooses
# its kernels at run time (DYNAMIC_ARCH: mixed-case core names such as "Haswell"; other builds report their build
# target in capitals and ignore OPENBLAS_CORETYPE).
function(blas_kernels_with environment result)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env ${environment} ${DRAPEGEN} simulate --alpha 30000 --resolution 6 --json
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "simulate for the BLAS check (${environment}) failed (${code}): ${out} ${err}")
  endif()
  string(JSON blas GET "${out}" blas_kernels)
  set(${result} "${blas}" PARENT_SCOPE)
endfunction()
blas_kernels_with(--unset=OPENBLAS_CORETYPE blas)
message(STATUS "BLAS kernels: ${blas}")
cmake_host_system_information(RESULT architecture QUERY OS_PLATFORM)  # (script mode has no CMAKE_HOST_SYSTEM_PROCESSOR)
if(architecture MATCHES "x86_64|AMD64" AND blas MATCHES "^OpenBLAS [A-Z][a-z]" AND EXISTS /proc/cpuinfo)
  file(READ /proc/cpuinfo cpuinfo LIMIT 20000)
  if(blas STREQUAL "OpenBLAS Prescott" AND cpuinfo MATCHES " avx2 " AND cpuinfo MATCHES " fma ")
    message(FATAL_ERROR "drapegen runs on OpenBLAS's Prescott kernels on a CPU with AVX2 and FMA")
  endif()
  blas_kernels_with(OPENBLAS_CORETYPE=Prescott blas)
  if(NOT blas STREQUAL "OpenBLAS Prescott")
    message(FATAL_ERROR "the user's OPENBLAS_CORETYPE=Prescott was not kept: ${blas}")
  endif()
endif()
