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
# The installed tools run from the prefix without LD_LIBRARY_PATH (their RPATH), when
# the build has them (EXPECT_TOOL: SELSEG_BUILD_APPS).
if(EXPECT_TOOL)
  if(EXISTS ${PREFIX}/bin/pcl_selective_seg)
    run(${CMAKE_COMMAND} -E env --unset=LD_LIBRARY_PATH ${PREFIX}/bin/pcl_selective_seg -h)
  else()
    message(FATAL_ERROR "pcl_selective_seg not installed to ${PREFIX}/bin")
  endif()
endif()
