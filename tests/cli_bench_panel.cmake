# Runs `probecast bench panel` small on a 2024-style Looking Glass calibration: a record per way
# with every phase timed, each panel against the full-quality one, and the ways ordered as the
# views' quality says (4x MSAA closer to full quality than one sample or half-size views, views of
# half the width closer than views of half the size each side).
file(REMOVE_RECURSE ${WORK})
execute_process(COMMAND ${PROBECAST} bench panel --looking-glass ${CALIBRATION} --size 24x32 --grid 4,4,4 --spp 8
                        --updates 1 --repeats 1 --json ${WORK}/panel.json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "bench panel failed (${rc}): ${out}")
endif()
file(READ ${WORK}/panel.json json)
string(JSON n LENGTH "${json}" ways)
if(NOT n EQUAL 5)
  message(FATAL_ERROR "expected the 5 default ways, got ${n}")
endif()
string(JSON cells GET "${json}" display subpixel_cells)
string(JSON views GET "${json}" display views 0)
if(NOT cells EQUAL 2 OR NOT views EQUAL 11)
  message(FATAL_ERROR "the display: ${cells} cells, ${views} columns of views")
endif()
foreach(i 0 1 2 3 4)
  string(JSON way GET "${json}" ways ${i} way)
  string(JSON frame GET "${json}" ways ${i} frame_ms)
  string(JSON interleave GET "${json}" ways ${i} interleave_ms)
  string(JSON psnr${i} GET "${json}" ways ${i} psnr_vs_full_db)
  if(NOT frame GREATER 0 OR NOT interleave GREATER 0 OR NOT psnr${i} GREATER 10)
    message(FATAL_ERROR "way ${way}: frame ${frame} ms, interleave ${interleave} ms, ${psnr${i}} dB")
  endif()
endforeach()
# ways: msaa4, msaa1, half, narrow, multiview
if(NOT psnr0 GREATER psnr1 OR NOT psnr0 GREATER psnr2 OR NOT psnr3 GREATER psnr2 OR NOT psnr4 EQUAL psnr0)
  message(FATAL_ERROR "4x MSAA ${psnr0} dB, one sample ${psnr1}, half size ${psnr2}, half width ${psnr3}, multiview ${psnr4}")
endif()
message(STATUS "bench panel ok")
