# ctest driver (cmake -P): pcl_selective_seg_simulate's exit codes and messages on usage
# errors and unwritable outputs. Only the last output cases simulate a scan (the cube,
# a few milliseconds).
#   -DSIMULATE=<the simulator tool> -DWORK=<a scratch folder, emptied first>
if(NOT DEFINED SIMULATE)
  message(FATAL_ERROR "simulate_tool_exit_codes.cmake: -DSIMULATE=... is missing")
endif()

set(failures "")
set(TOOL ${SIMULATE})
include(${CMAKE_CURRENT_LIST_DIR}/expect_exit_code.cmake)

expect(0 "" -h)
expect(2 "Unknown argument '-bogus'" -bogus 1)
expect(2 "needs a value > 0" -density 0)
expect(2 "Option -hole_radius_deg needs a value in \\[0, 57.29\\]" -hole_radius_deg 57.3)
expect(0 "" -hole_radius_deg 57.29)
expect(2 "jitter" -jitter 1.5)
expect(2 "jitter" -jitter -0.1)
# A repeated option (the first value was used silently).
expect(2 "Option -density is given more than once" -density 2 -density 3)
expect(2 "Option -o is given more than once" -o a.pcd -o b.pcd)
# More rays than the simulator casts (1e8): it cast 1e8, about a minute and 6 GB,
# without a word. The message gives the largest density of the scene.
expect(2 "casts at most 100000000: use -density 17241.37 or less" -density 1e5)
expect(2 "use -density 49261.08 or less" -scene chair -density 49261.09)
expect(2 "use -density 2024.29 or less" -scene door -density 1e300)

# Fewer than one ray: the library cast one, with a warning, and the tool wrote it.
expect(2 "fewer than one: use -density 0.000172 or more" -density 1e-300)
# The output is checked before the simulation (a folder was found after it, with a
# wrong message, and a FIFO was replaced by a regular file) and written as the other
# tools write theirs (OutputTransaction).
if(DEFINED WORK)
  file(REMOVE_RECURSE ${WORK})
  file(MAKE_DIRECTORY ${WORK}/folder.pcd)
  file(WRITE ${WORK}/folder.pcd.tmp "the user's own file\n")
  expect(1 "cannot write '.*folder.pcd': it is a folder" -o ${WORK}/folder.pcd)
  file(READ ${WORK}/folder.pcd.tmp kept)
  if(NOT kept STREQUAL "the user's own file\n")
    set(failures "${failures}\n  a failed write removed the user's file OUT.tmp")
  endif()
  find_program(MKFIFO mkfifo)
  if(MKFIFO)
    execute_process(COMMAND ${MKFIFO} ${WORK}/fifo.pcd)
    expect(1 "cannot write '.*fifo.pcd': it is not a regular file" -o ${WORK}/fifo.pcd)
  endif()
  expect(0 "" -o ${WORK}/cube.pcd)
  if(NOT EXISTS ${WORK}/cube.pcd)
    set(failures "${failures}\n  -o ${WORK}/cube.pcd wrote nothing")
  endif()
  # Every ray dropped: an empty cloud, which no tool reads, was written with exit 0.
  expect(1 "No ray returned a point" -dropout 0.999999 -o ${WORK}/none.pcd)
  if(EXISTS ${WORK}/none.pcd)
    set(failures "${failures}\n  an empty simulation wrote ${WORK}/none.pcd")
  endif()
  file(REMOVE_RECURSE ${WORK})
endif()
# An empty or option-like file name (-o -h printed the help; -o "" wrote nothing).
execute_process(COMMAND ${SIMULATE} -o "" RESULT_VARIABLE rc ERROR_VARIABLE err
  OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "Option -o needs a file name")
  set(failures "${failures}\n  -o '': exit ${rc} (${err})")
endif()
expect(2 "Option -o needs a file name, not an option" -o -h)

if(failures)
  message(FATAL_ERROR "unexpected exit codes or messages:${failures}")
endif()
