# ctest driver (cmake -P): pcl_selective_seg_viewer's exit codes on help, usage errors,
# unreadable input, a missing X display and -screenshot onto paths that are not regular
# files; none of these opens a window (the screenshots themselves:
# viewer_screenshot_test.cmake and viewer_screenshot_write_test.cmake).
#   -DVIEWER=<viewer> -DINPUT=<a readable scan> -DMISSING=<a path that does not exist>
foreach(var VIEWER INPUT MISSING)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "viewer_exit_codes.cmake: -D${var}=... is missing")
  endif()
endforeach()

set(failures "")
set(TOOL ${VIEWER})
include(${CMAKE_CURRENT_LIST_DIR}/expect_exit_code.cmake)

expect(0 "" -h)
expect(0 "" --help)
expect(2 "")
expect(2 "" ${INPUT} -unit_scale abc)
expect(2 "" ${INPUT} -unit_scale -1)
expect(2 "" ${INPUT} -merge_deg)
expect(2 "" ${INPUT} -split_deg 1x)
expect(2 "" ${INPUT} -size 640)
expect(2 "" ${INPUT} -size 640x480junk)
expect(2 "" ${INPUT} -view mesh,leaves)
expect(2 "" ${INPUT} -normal_step -3)
expect(2 "" ${INPUT} -normal_rings 0)
expect(2 "" ${INPUT} -no_such_option)
expect(2 "" ${INPUT} ${INPUT})
# A repeated option (the first value was used silently).
expect(2 "" ${INPUT} -split_deg 5 -split_deg 30)
expect(2 "" ${INPUT} -ignore_viewpoint -ignore_viewpoint)
expect(1 "" ${MISSING} -screenshot ${MISSING}.png)
# Found by review (session 26): an empty screenshot name ran the interactive window
# (a hang under xvfb), a size beyond int wrapped, scales beyond float's range blamed
# the points, and -roi_* without -roi did nothing.
foreach(flag -screenshot -roi_json) # an empty argument: not through expect()'s list
  execute_process(COMMAND ${VIEWER} ${INPUT} ${flag} ""
    RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err TIMEOUT 120)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "${flag} needs a file name")
    set(failures "${failures}\n  '${flag} \"\"': exit '${rc}', expected 2 (${err})")
  endif()
endforeach()
expect(2 "" ${INPUT} -size 4294967360x100)
expect(2 "-unit_scale needs a number" ${INPUT} -unit_scale 1e300)
expect(2 "-unit_scale needs a number" ${INPUT} -unit_scale 1e-300)
expect(2 "applies with -roi" ${INPUT} -roi_max_regions 1)
# An option where a value should be was taken as the value (a file named -wireframe),
# and a .jpg name got PNG bytes.
expect(2 "needs a value, not the option '-wireframe'" ${INPUT} -screenshot -wireframe)
expect(2 "needs a value, not the option '-roi'" ${INPUT} -roi_json -roi)
expect(2 "give a name ending in .png" ${INPUT} -screenshot ${MISSING}.jpg)
# A screenshot in a folder that does not exist: refused before the scan is segmented.
expect(1 "check that the folder exists" ${INPUT} -screenshot ${MISSING}/x.png)
# A screenshot naming the input would replace the scan with a PNG: refused before the
# scan is read (so, before any rendering), the copy unchanged.
get_filename_component(scratch ${MISSING} DIRECTORY)
set(copy ${scratch}/viewer_exit_codes_input.pcd)
configure_file(${INPUT} ${copy} COPYONLY)
file(SHA256 ${copy} before)
expect(2 "" ${copy} -ignore_viewpoint -screenshot ${copy})
expect(2 "" ${copy} -ignore_viewpoint -screenshot ${scratch}/./viewer_exit_codes_input.pcd)
file(SHA256 ${copy} after)
if(NOT before STREQUAL after)
  set(failures "${failures}\n  -screenshot onto the input changed the input")
endif()
file(REMOVE ${copy})
# Without an X display: a message and exit 1, not VTK's abort.
set(TOOL ${CMAKE_COMMAND} -E env --unset=DISPLAY ${VIEWER})
expect(1 "" ${INPUT} -ignore_viewpoint -screenshot ${MISSING}.png)
# A screenshot path that is not a regular file is refused before any display is needed
# (a FIFO made the viewer wait for a reader for ever; the picture would have replaced
# a device), the FIFO left as it is.
set(out ${scratch}/viewer_exit_codes_out)
file(REMOVE_RECURSE ${out})
file(MAKE_DIRECTORY ${out}/folder.png)
execute_process(COMMAND mkfifo ${out}/fifo.png)
set(view ${INPUT} -ignore_viewpoint -size 320x240 -screenshot)
expect(1 "'.*fifo.png': it is not a regular file" ${view} ${out}/fifo.png)
expect(1 "'.*folder.png': it is a folder" ${view} ${out}/folder.png)
execute_process(COMMAND test -p ${out}/fifo.png RESULT_VARIABLE fifo_rc)
if(NOT fifo_rc EQUAL 0)
  set(failures "${failures}\n  the FIFO given to -screenshot is not a FIFO any more")
endif()
file(REMOVE_RECURSE ${out})

if(failures)
  message(FATAL_ERROR "pcl_selective_seg_viewer exit codes:${failures}")
endif()
