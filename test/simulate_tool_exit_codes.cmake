# ctest driver (cmake -P): pcl_selective_seg_simulate's exit codes and messages on usage
# errors. None of these cases simulates a scan.
#   -DSIMULATE=<the simulator tool>
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

if(failures)
  message(FATAL_ERROR "unexpected exit codes or messages:${failures}")
endif()
