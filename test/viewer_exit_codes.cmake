# ctest driver (cmake -P): pcl_selective_seg_viewer's exit codes on help, usage errors,
# unreadable input and a missing X display. None of these cases opens a window, so no X
# server is needed.
#   -DVIEWER=<viewer> -DINPUT=<a readable scan> -DMISSING=<a path that does not exist>
foreach(var VIEWER INPUT MISSING)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "viewer_exit_codes.cmake: -D${var}=... is missing")
  endif()
endforeach()

set(failures "")
set(launcher "")
# expect(<exit code> <argument>...): run ${launcher} viewer <argument>..., compare its
# exit code.
function(expect code)
  execute_process(COMMAND ${launcher} ${VIEWER} ${ARGN}
    RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
  if(NOT rc EQUAL code)
    set(failures "${failures}\n  '${ARGN}': exit '${rc}', expected ${code} (${err})"
      PARENT_SCOPE)
  endif()
endfunction()

expect(0 -h)
expect(0 --help)
expect(2)
expect(2 ${INPUT} -unit_scale abc)
expect(2 ${INPUT} -unit_scale -1)
expect(2 ${INPUT} -merge_deg)
expect(2 ${INPUT} -split_deg 1x)
expect(2 ${INPUT} -size 640)
expect(2 ${INPUT} -size 640x480junk)
expect(2 ${INPUT} -view mesh,leaves)
expect(2 ${INPUT} -normal_step -3)
expect(2 ${INPUT} -normal_rings 0)
expect(2 ${INPUT} -no_such_option)
expect(2 ${INPUT} ${INPUT})
# A repeated option (the first value was used silently).
expect(2 ${INPUT} -split_deg 5 -split_deg 30)
expect(2 ${INPUT} -ignore_viewpoint -ignore_viewpoint)
expect(1 ${MISSING} -screenshot ${MISSING}.png)
# A screenshot naming the input would replace the scan with a PNG: refused before the
# scan is read (so, before any rendering), the copy unchanged.
get_filename_component(scratch ${MISSING} DIRECTORY)
set(copy ${scratch}/viewer_exit_codes_input.pcd)
configure_file(${INPUT} ${copy} COPYONLY)
file(SHA256 ${copy} before)
expect(2 ${copy} -ignore_viewpoint -screenshot ${copy})
expect(2 ${copy} -ignore_viewpoint -screenshot ${scratch}/./viewer_exit_codes_input.pcd)
file(SHA256 ${copy} after)
if(NOT before STREQUAL after)
  set(failures "${failures}\n  -screenshot onto the input changed the input")
endif()
file(REMOVE ${copy})
# Without an X display: a message and exit 1, not VTK's abort.
set(launcher ${CMAKE_COMMAND} -E env --unset=DISPLAY)
expect(1 ${INPUT} -ignore_viewpoint -screenshot ${MISSING}.png)

if(failures)
  message(FATAL_ERROR "pcl_selective_seg_viewer exit codes:${failures}")
endif()
