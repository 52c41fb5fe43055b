# Install the build tree to PREFIX, then build and run the consumer project against it.
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}")
  endif()
endfunction()
file(REMOVE_RECURSE ${PREFIX} ${WORK_DIR})
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${PREFIX})
# The licence goes with the package (BSD-3-Clause: binaries must carry the notice).
if(NOT EXISTS ${PREFIX}/share/doc/pcl_selective_seg/LICENSE)
  message(FATAL_ERROR "LICENSE not installed to ${PREFIX}/share/doc/pcl_selective_seg")
endif()
run(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR} -DCMAKE_PREFIX_PATH=${PREFIX}
    -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${WORK_DIR} -j2)
run(${WORK_DIR}/consumer)
run(${WORK_DIR}/consumer_custom_point)
if(EXISTS ${WORK_DIR}/consumer_native)
  run(${WORK_DIR}/consumer_native)
endif()
# A program that compiles the bodies for its own point type makes no copies of the
# library's non-inline PointXYZ members (extern templates, also under
# PCL_NO_PRECOMPILE); and whatever a program defines, the library binds to its own
# (-Bsymbolic), not to copies compiled with the program's flags (without OpenMP, or
# for another CPU: another Eigen alignment).
find_program(NM nm)
find_program(READELF readelf)
if(NM)
  execute_process(COMMAND ${NM} -D -C --defined-only ${WORK_DIR}/consumer_custom_point
                  OUTPUT_VARIABLE exported RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "nm failed on consumer_custom_point")
  endif()
  string(REGEX MATCHALL
         "[^\n]*selective_seg::[A-Za-z]+<pcl::PointXYZ>::(insertPoints|computeAdaptiveLeaves|extract|reconstruct|triangulate)\\([^\n]*"
         copies "${exported}")
  if(copies)
    message(FATAL_ERROR "consumer_custom_point defines the library's PointXYZ "
                        "instantiations itself:\n${copies}")
  endif()
endif()
if(READELF)
  file(GLOB library ${PREFIX}/lib*/libpcl_selective_seg.so)
  execute_process(COMMAND ${READELF} -d ${library} OUTPUT_VARIABLE dynamic
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0 OR NOT dynamic MATCHES "SYMBOLIC")
    message(FATAL_ERROR "${library} is not linked with -Bsymbolic")
  endif()
endif()
# The installed tools run from the prefix without LD_LIBRARY_PATH (their RPATH), when
# the build has them (EXPECT_TOOL: SELSEG_BUILD_APPS).
if(EXPECT_TOOL)
  if(EXISTS ${PREFIX}/bin/pcl_selective_seg)
    run(${CMAKE_COMMAND} -E env --unset=LD_LIBRARY_PATH ${PREFIX}/bin/pcl_selective_seg -h)
  else()
    message(FATAL_ERROR "pcl_selective_seg not installed to ${PREFIX}/bin")
  endif()
endif()
