# ctest driver (cmake -P): pcl_selective_seg_viewer's -screenshot when the write fails
# part way, and when it succeeds, under a virtual X server. The picture is written to a
# temporary and renamed into place (OutputTransaction): a failed write leaves no partial
# picture and the old one unchanged. The server runs with -noreset: otherwise it resets
# when the viewer disconnects and signals xvfb-run (SIGUSR1) while it removes its
# temporary folder, which then fails now and then (exit 5, a stray Xvfb). Like the
# other viewer_screenshot_* tests, not run under the sanitizers (the OpenGL drivers are
# not instrumented, and leak).
#   -DXVFB_RUN=<xvfb-run> -DVIEWER=<viewer> -DINPUT=<a readable scan>
#   -DOUT=<a scratch folder, emptied first>
foreach(var XVFB_RUN VIEWER INPUT OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "viewer_screenshot_write_test.cmake: -D${var}=... is missing")
  endif()
endforeach()

set(failures "")
include(${CMAKE_CURRENT_LIST_DIR}/expect_exit_code.cmake)
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
file(WRITE ${OUT}/old.png "old\n")
set(view ${INPUT} -ignore_viewpoint -size 320x240 -screenshot ${OUT}/old.png)
set(xvfb ${XVFB_RUN} -a -s "-screen 0 1280x1024x24 -noreset")
# A file size limit of 4 KiB (the picture is about 130 KiB): the write fails.
set(TOOL ${xvfb} sh -c "ulimit -f 4 && trap '' XFSZ && exec \"$0\" \"$@\"" ${VIEWER})
expect(1 "Cannot write the PNG '.*old.png'" ${view})
file(READ ${OUT}/old.png old)
file(GLOB left RELATIVE ${OUT} ${OUT}/*)
if(NOT old STREQUAL "old\n" OR NOT left STREQUAL "old.png")
  set(failures "${failures}\n  a failed screenshot changed the folder: '${left}', "
    "old.png '${old}'")
endif()
set(TOOL ${xvfb} ${VIEWER})
expect(0 "" ${view})
file(SIZE ${OUT}/old.png size)
file(GLOB left RELATIVE ${OUT} ${OUT}/*)
if(size LESS 1024 OR NOT left STREQUAL "old.png")
  set(failures "${failures}\n  the screenshot has ${size} bytes, the folder '${left}'")
endif()
file(REMOVE_RECURSE ${OUT})

if(failures)
  message(FATAL_ERROR "pcl_selective_seg_viewer screenshots:${failures}")
endif()
