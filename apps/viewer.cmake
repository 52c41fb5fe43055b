# pcl_selective_seg_viewer: the segmentation shown as the paper's figures (mesh and
# labeled octree, seen from the sensor). Included from apps/CMakeLists.txt, after
# selseg_apps_common; the only target that links pcl_visualization (and so VTK's
# rendering). Skipped, with a message, when PCL was built without visualization.
find_package(PCL 1.12 QUIET COMPONENTS common io visualization)
if(NOT TARGET pcl_visualization)
  message(STATUS "pcl_visualization not found: pcl_selective_seg_viewer is not built")
  return()
endif()

add_executable(pcl_selective_seg_viewer
  ${CMAKE_CURRENT_LIST_DIR}/pcl_selective_seg_viewer.cpp)
target_link_libraries(pcl_selective_seg_viewer PRIVATE
  selseg_apps_common pcl_visualization)
target_compile_options(pcl_selective_seg_viewer PRIVATE -Wall -Wextra)
install(TARGETS pcl_selective_seg_viewer RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
