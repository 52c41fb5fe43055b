# ctest driver (cmake -P): pcl_selective_seg_selective_loop's exit codes and messages on
# help, usage errors and an output folder that cannot be made, and that a failed run
# leaves its output folder as it was (the last cases simulate the cube and the chair
# with one round: about 2 s).
#   -DLOOP=<the loop tool> -DBLOCKED=<a regular file: no folder can be made under it>
#   -DWORK=<a scratch folder, emptied first>
foreach(var LOOP BLOCKED WORK)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "loop_tool_exit_codes.cmake: -D${var}=... is missing")
  endif()
endforeach()
file(WRITE ${BLOCKED} "not a folder\n")

set(failures "")
set(TOOL ${LOOP})
include(${CMAKE_CURRENT_LIST_DIR}/expect_exit_code.cmake)

expect(0 "" -h)
# The help states the defaults the tool starts from (it once said tiles of 2 coarse
# steps while the tool used 1).
execute_process(COMMAND ${LOOP} -h OUTPUT_VARIABLE help ERROR_VARIABLE help_err)
foreach(line "-window_steps X[^\n]*\\(default 1\\)" "-iterations N[^\n]*\\(default 3\\)"
             "-coarse_factor X[^\n]*\\(default 3\\)")
  if(NOT "${help}${help_err}" MATCHES "${line}")
    set(failures "${failures}\n  '-h' does not show '${line}'")
  endif()
endforeach()
expect(2 "")
expect(2 "Unknown argument '-bogus'" -bogus 1)
expect(2 "Missing value of '-out'" -out)
expect(2 "Give -out FOLDER" -scenes cube)
expect(2 "Unknown scene 'sofa'" -out ${BLOCKED}.d -scenes sofa)
expect(2 "Scene 'cube' is listed twice" -out ${BLOCKED}.d -scenes cube,cube)
# The loop sets the regions' budget; these were once accepted and still applied.
expect(2 "-roi_max_regions does not apply here" -out ${BLOCKED}.d -roi_max_regions 2)
expect(2 "-roi_max_sr does not apply here" -out ${BLOCKED}.d -roi_max_sr 1e-5)
# Out of range before any scan (these failed only after the uniform scans, exit 1).
expect(2 "1 <= coarse_factor <= 100" -out ${BLOCKED}.d -coarse_factor 1e300)
expect(2 "window_steps 0 or in" -out ${BLOCKED}.d -window_steps 1e-12)
# A repeated option (the first value was used silently).
expect(2 "Option -iterations is given more than once"
  -out ${BLOCKED}/out -iterations 1 -iterations 2 -scenes cube)
expect(1 "Cannot make the output folder '.*': .*writable folder"
  -out ${BLOCKED}/out -scenes cube)
expect(1 "Cannot make the output folder" -out ${BLOCKED} -scenes cube)

# Failed runs leave the output folder as it was: no partial outputs, no temporaries, old
# files unchanged. Every file is staged and put in place at the end of the run; here
# chair.dat, a folder, is refused after the cube's files were all written.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/full/chair.dat)
file(WRITE ${WORK}/full/cube.dat "old\n")
# contents(<variable> <folder>): the names in the folder, sorted
function(contents var folder)
  file(GLOB names RELATIVE ${folder} ${folder}/*)
  list(SORT names)
  set(${var} "${names}" PARENT_SCOPE)
endfunction()
expect(1 "cannot write '.*chair.dat': it is a folder"
  -out ${WORK}/full -scenes cube,chair -iterations 1)
contents(left ${WORK}/full)
file(READ ${WORK}/full/cube.dat cube_dat)
if(NOT left STREQUAL "chair.dat;cube.dat" OR NOT cube_dat STREQUAL "old\n")
  set(failures "${failures}\n  a failed run changed its folder: '${left}', cube.dat "
    "'${cube_dat}'")
endif()
# A budget fraction too small for the coarse scan (which the budget includes) is a
# runtime error (it depends on the scan) whose message gives a fraction that works;
# the folder the run made (and its parent) is removed. That fraction then runs.
set(fresh ${WORK}/fresh/out)
expect(1 "budget of 0 points, less than the coarse scan's .*: give -budget_fraction [0-9.e+-]+ or more"
  -out ${fresh} -scenes cube -iterations 1 -budget_fraction 1e-300)
expect(1 "budget of [0-9]+ points, less than the coarse scan's"
  -out ${fresh} -scenes cube -iterations 1 -budget_fraction 0.05)
if(EXISTS ${WORK}/fresh)
  set(failures "${failures}\n  a failed run left the folder it made")
endif()
execute_process(COMMAND ${LOOP} -out ${fresh} -scenes cube -iterations 1
  -budget_fraction 1e-300 OUTPUT_QUIET ERROR_VARIABLE err)
string(REGEX MATCH "give -budget_fraction ([0-9.e+-]+) or more" _ "${err}")
expect(0 "" -out ${fresh} -scenes cube -iterations 1 -budget_fraction ${CMAKE_MATCH_1})
contents(written ${fresh})
set(all_files cube.dat cube_boundary_errors.dat cube_coarse.pcd cube_coarse_rois.json
  cube_dense.pcd cube_min_voxel.txt cube_refined.pcd cube_windows.json table.md)
if(NOT written STREQUAL "${all_files}")
  set(failures "${failures}\n  a run with -budget_fraction ${CMAKE_MATCH_1} wrote "
    "'${written}'")
endif()
file(REMOVE_RECURSE ${WORK})

if(failures)
  message(FATAL_ERROR "unexpected exit codes or messages:${failures}")
endif()
