# Tests of apps/pcl_selective_seg_viewer, included from test/CMakeLists.txt. The
# screenshot tests render the bundled scan off screen under xvfb-run and check that
# the picture shows segments in distinct hues; without xvfb-run they are skipped.
if(NOT TARGET pcl_selective_seg_viewer)
  message(STATUS "pcl_selective_seg_viewer is not built: its tests are skipped")
  return()
endif()

set(SELSEG_VIEWER_SCAN ${PROJECT_SOURCE_DIR}/data/table_scene_mug_stereo_textured.pcd)

add_test(NAME viewer_exit_codes
  COMMAND ${CMAKE_COMMAND}
    -DVIEWER=$<TARGET_FILE:pcl_selective_seg_viewer>
    -DINPUT=${SELSEG_VIEWER_SCAN}
    -DMISSING=${CMAKE_CURRENT_BINARY_DIR}/no_such_scan.pcd
    -P ${CMAKE_CURRENT_LIST_DIR}/viewer_exit_codes.cmake)
set_tests_properties(viewer_exit_codes PROPERTIES TIMEOUT 300)

find_program(XVFB_RUN xvfb-run)

if(NOT XVFB_RUN)
  message(STATUS "xvfb-run not found (apt-get install xvfb xauth libgl1-mesa-dri): "
    "the viewer's screenshot tests are skipped")
  return()
endif()
if(NOT TARGET VTK::IOImage)
  find_package(VTK QUIET)
endif()
if(NOT TARGET VTK::IOImage)
  message(STATUS "VTK's IOImage not found: the viewer's screenshot tests are skipped")
  return()
endif()

add_executable(check_screenshot ${CMAKE_CURRENT_LIST_DIR}/check_screenshot.cpp)
target_link_libraries(check_screenshot PRIVATE
  VTK::IOImage VTK::CommonDataModel VTK::CommonCore)
target_compile_options(check_screenshot PRIVATE -Wall -Wextra)

# viewer_screenshot_write: a screenshot whose write fails part way, then one that works.
add_test(NAME viewer_screenshot_write
  COMMAND ${CMAKE_COMMAND}
    -DXVFB_RUN=${XVFB_RUN}
    -DVIEWER=$<TARGET_FILE:pcl_selective_seg_viewer>
    -DINPUT=${SELSEG_VIEWER_SCAN}
    -DOUT=${CMAKE_CURRENT_BINARY_DIR}/viewer_screenshot_write_out
    -P ${CMAKE_CURRENT_LIST_DIR}/viewer_screenshot_write_test.cmake)
set_tests_properties(viewer_screenshot_write PROPERTIES RESOURCE_LOCK xvfb TIMEOUT 300)

# viewer_screenshot_<view>: at 640x480, at least 6 of the 12 hue sectors must each
# hold 1000 saturated pixels (0.3% of the picture; the mug scene gives over 3000).
foreach(view mesh octree)
  add_test(NAME viewer_screenshot_${view}
    COMMAND ${CMAKE_COMMAND}
      -DXVFB_RUN=${XVFB_RUN}
      -DVIEWER=$<TARGET_FILE:pcl_selective_seg_viewer>
      -DCHECKER=$<TARGET_FILE:check_screenshot>
      -DINPUT=${SELSEG_VIEWER_SCAN}
      -DVIEWER_ARGS=-ignore_viewpoint
      -DPNG=${CMAKE_CURRENT_BINARY_DIR}/viewer_mug_${view}.png
      -DVIEW=${view} -DWIDTH=640 -DHEIGHT=480 -DMIN_HUES=6 -DMIN_PIXELS=1000
      -P ${CMAKE_CURRENT_LIST_DIR}/viewer_screenshot_test.cmake)
  # One virtual X server at a time: concurrent xvfb-run -a can pick the same display.
  set_tests_properties(viewer_screenshot_${view} PROPERTIES
    RESOURCE_LOCK xvfb TIMEOUT 300)
endforeach()
