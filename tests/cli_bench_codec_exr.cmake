# Writes DWAB, PIZ and B44 EXRs with OpenEXR (write_test_exrs) and runs `probecast bench codec` on
# them; then a truncated EXR in the folder must fail with a message naming it.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/maps)
execute_process(COMMAND ${WRITE_EXRS} ${WORK}/maps DWAB PIZ B44 RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "write_test_exrs failed (${rc}): ${err}")
endif()
execute_process(COMMAND ${PROBECAST} --quiet bench codec --envmaps ${WORK}/maps --json ${WORK}/codec.json --frames 2
                        --normals 64
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "bench codec failed (${rc}): ${out} ${err}")
endif()
if(err MATCHES "representation ")
  message(FATAL_ERROR "bench codec --quiet still printed progress: ${err}")
endif()
file(READ ${WORK}/codec.json json)
foreach(name test_DWAB.exr test_PIZ.exr test_B44.exr)
  if(NOT json MATCHES "${name}")
    message(FATAL_ERROR "${name} is not in the JSON")
  endif()
endforeach()
string(JSON bytes GET "${json}" representations zh3 bytes_per_probe)
if(NOT bytes EQUAL 16)
  message(FATAL_ERROR "zh3 bytes_per_probe is ${bytes}, expected 16")
endif()

# A truncated file: a clear error naming it, exit code 1, no crash.
execute_process(COMMAND bash -c "head -c 200 ${WORK}/maps/test_PIZ.exr > ${WORK}/maps/truncated.exr")
execute_process(COMMAND ${PROBECAST} bench codec --envmaps ${WORK}/maps --json ${WORK}/bad.json --frames 2 --normals 64
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 1 OR NOT err MATCHES "truncated.exr: cannot read EXR")
  message(FATAL_ERROR "truncated EXR: expected exit 1 and an error naming the file, got ${rc}: ${out} ${err}")
endif()
