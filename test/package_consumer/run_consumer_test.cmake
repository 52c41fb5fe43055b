# Install the build tree to PREFIX, then build and run the consumer project against it.
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}")
  endif()
endfunction()
#
# With STATIC_FROM_SOURCE=<source dir>, the library is first configured and built there
# as a static library (BUILD_SHARED_LIBS=OFF, only the library), and that is installed.
file(REMOVE_RECURSE ${PREFIX} ${WORK_DIR})
set(static OFF)
if(EXPECT_STATIC)
  set(static ON)
endif()
if(STATIC_FROM_SOURCE)
  set(static ON)
  set(BUILD_DIR ${WORK_DIR}/library)
  run(${CMAKE_COMMAND} -S ${STATIC_FROM_SOURCE} -B ${BUILD_DIR} -DCMAKE_BUILD_TYPE=Release
      -DBUILD_SHARED_LIBS=OFF -DSELSEG_BUILD_APPS=OFF -DBUILD_TESTING=OFF)
  run(${CMAKE_COMMAND} --build ${BUILD_DIR} -j2)
  set(EXPECT_TOOL OFF)
endif()
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${PREFIX})
file(GLOB shared_library ${PREFIX}/lib*/libpcl_selective_seg.so*)
file(GLOB static_library ${PREFIX}/lib*/libpcl_selective_seg.a)
if(static AND (shared_library OR NOT static_library))
  message(FATAL_ERROR "BUILD_SHARED_LIBS=OFF installed '${shared_library}' and '${static_library}'")
elseif(NOT static AND (static_library OR NOT shared_library))
  message(FATAL_ERROR "the default build installed '${shared_library}' and '${static_library}'")
endif()
# The licence goes with the package (BSD-3-Clause: binaries must carry the notice).
if(NOT EXISTS ${PREFIX}/share/doc/pcl_selective_seg/LICENSE)
  message(FATAL_ERROR "LICENSE not installed to ${PREFIX}/share/doc/pcl_selective_seg")
endif()
# A static library holds code compiled with its own flags, and the program's link keeps
# one copy of each inline function: it must be built with the program's SIMD flags (as
# a subproject is), so the -march=native program is left out there (README).
set(consumer_dir ${WORK_DIR}/consumer)
run(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${consumer_dir} -DCMAKE_PREFIX_PATH=${PREFIX}
    -DCMAKE_BUILD_TYPE=Release -DCONSUMER_EXPECT_STATIC=${static})
run(${CMAKE_COMMAND} --build ${consumer_dir} -j2)
run(${consumer_dir}/consumer)
run(${consumer_dir}/consumer_custom_point)
if(EXISTS ${consumer_dir}/consumer_native)
  run(${consumer_dir}/consumer_native)
endif()
# A program that compiles the bodies for its own point type makes no copies of the
# library's non-inline PointXYZ members (extern templates, also under
# PCL_NO_PRECOMPILE); and whatever a program defines, the library binds to its own
# (-Bsymbolic), not to copies compiled with the program's flags (without OpenMP, or
# for another CPU: another Eigen alignment).
find_program(NM nm)
find_program(READELF readelf)
if(NM AND NOT static)
  execute_process(COMMAND ${NM} -D -C --defined-only ${consumer_dir}/consumer_custom_point
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
if(READELF AND NOT static)
  file(GLOB library ${PREFIX}/lib*/libpcl_selective_seg.so)
  execute_process(COMMAND ${READELF} -d ${library} OUTPUT_VARIABLE dynamic
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0 OR NOT dynamic MATCHES "SYMBOLIC")
    message(FATAL_ERROR "${library} is not linked with -Bsymbolic")
  endif()
elseif(READELF)
  # The program holds the library: it needs no libpcl_selective_seg at run time.
  execute_process(COMMAND ${READELF} -d ${consumer_dir}/consumer OUTPUT_VARIABLE dynamic
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0 OR dynamic MATCHES "libpcl_selective_seg")
    message(FATAL_ERROR "the program linked against the static library needs a shared one")
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
