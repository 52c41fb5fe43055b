# ctest driver (cmake -P): render a scan with pcl_selective_seg_viewer -screenshot under
# a virtual X server, then check the picture with check_screenshot.
#   -DXVFB_RUN=<xvfb-run> -DVIEWER=<viewer> -DCHECKER=<check_screenshot>
#   -DINPUT=<scan> -DPNG=<output> -DVIEW=<layers> -DWIDTH=<px> -DHEIGHT=<px>
#   -DMIN_HUES=<n> -DMIN_PIXELS=<n> [-DVIEWER_ARGS=<arg;arg>]
foreach(var XVFB_RUN VIEWER CHECKER INPUT PNG VIEW WIDTH HEIGHT MIN_HUES MIN_PIXELS)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "viewer_screenshot_test.cmake: -D${var}=... is missing")
  endif()
endforeach()

file(REMOVE ${PNG})
# A 24-bit screen: xvfb-run's default 8-bit one has no true-colour visual for OpenGL.
execute_process(
  COMMAND ${XVFB_RUN} -a -s "-screen 0 1280x1024x24 -noreset"
    ${VIEWER} ${INPUT} ${VIEWER_ARGS} -view ${VIEW}
    -screenshot ${PNG} -size ${WIDTH}x${HEIGHT}
  RESULT_VARIABLE viewer_rc)
if(NOT viewer_rc EQUAL 0)
  message(FATAL_ERROR
    "pcl_selective_seg_viewer -screenshot exited with '${viewer_rc}', expected 0")
endif()

execute_process(
  COMMAND ${CHECKER} ${PNG} ${WIDTH} ${HEIGHT} ${MIN_HUES} ${MIN_PIXELS}
  RESULT_VARIABLE checker_rc)
if(NOT checker_rc EQUAL 0)
  message(FATAL_ERROR "check_screenshot rejected ${PNG} (exit '${checker_rc}')")
endif()
