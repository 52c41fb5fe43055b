# Simulated scans of the paper's scenes with ground-truth labels; included from
# apps/CMakeLists.txt, which finds PCL's io component.
add_executable(pcl_selective_seg_simulate
  ${CMAKE_CURRENT_LIST_DIR}/pcl_selective_seg_simulate.cpp)
target_link_libraries(pcl_selective_seg_simulate PRIVATE selseg_apps_common)
target_compile_options(pcl_selective_seg_simulate PRIVATE -Wall -Wextra)
install(TARGETS pcl_selective_seg_simulate RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
