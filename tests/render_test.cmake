# Runs drapegen render end to end on a small drape: EXR files that OpenEXR's own exrheader opens, a PNG preview,
# byte-identical files for the same seed, and one-line errors for bad meshes and unwritable outputs.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

include(${CMAKE_CURRENT_LIST_DIR}/expect_error.cmake)
include(${CMAKE_CURRENT_LIST_DIR}/json_number.cmake)
# expect_failure(EXIT NEEDLE ARGS...): `drapegen ARGS...` (a render) fails with a one-line error that says NEEDLE.
function(expect_failure code_expected needle)
  expect_drapegen_error(CODE ${code_expected} SUB render SAYS "${needle}" ARGS ${ARGN})
endfunction()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "'${ARGN}' failed (${code}): ${out} ${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

run(${DRAPEGEN} simulate --alpha 13923,11455,8821 --beta=-35390,-29660,-22042 --resolution 25 --init sine --seed 1
    --out ${WORK}/drape.ply)

# Three data points with noise, a preview, the JSON summary.
run(${DRAPEGEN} render --mesh ${WORK}/drape.ply --out ${WORK}/a.exr --orientations 3 --seed 5
    --preview ${WORK}/views.png --json)
json_number(views "${out}" views)
json_number(bytes "${out}" bytes_per_view)
if(NOT views EQUAL 12)
  message(FATAL_ERROR "expected 12 views: ${out}")
endif()
if(bytes LESS 500 OR bytes GREATER 20000)
  message(FATAL_ERROR "implausible bytes per view ${bytes}")
endif()
foreach(k 00 01 02)
  if(NOT EXISTS ${WORK}/a_${k}.exr)
    message(FATAL_ERROR "missing ${WORK}/a_${k}.exr")
  endif()
  # OpenEXR's own tool reads the file and sees the four depth channels and the cameras.
  run(${EXRHEADER} ${WORK}/a_${k}.exr)
  foreach(needle "view0.Z, 16-bit floating-point" "view3.Z, 16-bit floating-point" "view3.meshToCamera"
          "view0.K" "drapegen.noise" "drapegen.orientation" "view2.noiseSeed")
    string(FIND "${out}" "${needle}" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "exrheader a_${k}.exr shows no '${needle}': ${out}")
    endif()
  endforeach()
endforeach()
file(READ ${WORK}/views.png png_head LIMIT 8 HEX)
if(NOT png_head STREQUAL "89504e470d0a1a0a")
  message(FATAL_ERROR "preview is not a PNG")
endif()

# Same seed: byte-identical files; another seed: different files.
run(${DRAPEGEN} render --mesh ${WORK}/drape.ply --out ${WORK}/b.exr --orientations 3 --seed 5)
run(${DRAPEGEN} render --mesh ${WORK}/drape.ply --out ${WORK}/c.exr --orientations 3 --seed 6)
foreach(k 00 01 02)
  file(SHA256 ${WORK}/a_${k}.exr ha)
  file(SHA256 ${WORK}/b_${k}.exr hb)
  file(SHA256 ${WORK}/c_${k}.exr hc)
  if(NOT ha STREQUAL hb)
    message(FATAL_ERROR "same seed, different file: a_${k}.exr b_${k}.exr")
  endif()
  if(ha STREQUAL hc)
    message(FATAL_ERROR "different seeds, same file: a_${k}.exr c_${k}.exr")
  endif()
endforeach()

# The default renderer, OpenGL through OSMesa, names its Mesa driver.
run(${DRAPEGEN} render --mesh ${WORK}/drape.ply --out ${WORK}/gl.exr --orientations 1 --renderer osmesa --json)
string(JSON renderer GET "${out}" renderer)
if(NOT renderer MATCHES "llvmpipe|softpipe")
  message(FATAL_ERROR "--renderer osmesa rendered with '${renderer}'")
endif()

# One data point: exactly the --out path; clean depth.
run(${DRAPEGEN} render --mesh ${WORK}/drape.ply --out ${WORK}/clean.exr --orientations 1 --noise none)
if(NOT EXISTS ${WORK}/clean.exr OR EXISTS ${WORK}/clean_00.exr)
  message(FATAL_ERROR "--orientations 1 did not write --out itself")
endif()
run(${EXRHEADER} ${WORK}/clean.exr)
if(NOT out MATCHES "drapegen.noise \\(type string\\): \"none\"")
  message(FATAL_ERROR "--noise none: clean.exr does not record a clean depth: ${out}")
endif()

# Bad meshes: missing, empty, non-finite, out of view (millimetres); unwritable outputs.
expect_failure(1 "'${WORK}/missing.ply': cannot open" render --mesh ${WORK}/missing.ply --out ${WORK}/x.exr)
file(WRITE ${WORK}/empty.ply "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n")
expect_failure(1 "'${WORK}/empty.ply': the file has no vertices" render --mesh ${WORK}/empty.ply --out ${WORK}/x.exr)
file(WRITE ${WORK}/nan.ply "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\nnan 0.1 0\n0 0.1 0\n3 0 1 2\n")
expect_failure(1 "'${WORK}/nan.ply': non-finite vertex coordinate" render --mesh ${WORK}/nan.ply
               --out ${WORK}/x.exr)
file(WRITE ${WORK}/mm.ply "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n-150 -150 0\n150 -150 0\n0 150 0\n3 0 1 2\n")
expect_failure(1 "mesh is out of the camera's view" render --mesh ${WORK}/mm.ply --out ${WORK}/x.exr)
expect_failure(3 "cannot write '/nonexistent-dir/x" render --mesh ${WORK}/drape.ply --out /nonexistent-dir/x.exr)
expect_failure(3 "cannot write '/nonexistent-dir/v.png'" render --mesh ${WORK}/drape.ply --out ${WORK}/x.exr
               --preview /nonexistent-dir/v.png)
expect_failure(1 "--orientations must be between 1 and 360" render --mesh ${WORK}/drape.ply --out ${WORK}/x.exr
               --orientations 0)
expect_failure(1 "unknown EXR compression 'jpeg'" render --mesh ${WORK}/drape.ply --out ${WORK}/x.exr
               --compression jpeg)
expect_failure(1 "quantum must be 0 (none) or in [1e-9, 0.01] m" render --mesh ${WORK}/drape.ply
               --out ${WORK}/x.exr --quantum -1)
# A denormal quantum overflowed z / q to infinity in every stored depth; outputs over the input or over each other.
expect_drapegen_error(CODE 1 SUB render SAYS "quantum must be 0 (none) or in [1e-9, 0.01] m"
                      ARGS render --mesh ${WORK}/drape.ply --out ${WORK}/x.exr --quantum 1e-320)
expect_drapegen_error(CODE 1 SUB render SAYS "would overwrite the input mesh"
                      ARGS render --mesh ${WORK}/drape.ply --out ${WORK}/drape.ply --orientations 1)
expect_drapegen_error(CODE 1 SUB render SAYS "is two of the outputs"
                      ARGS render --mesh ${WORK}/drape.ply --out ${WORK}/c.exr --orientations 2
                      --preview ${WORK}/c_00.exr)
