# ctest driver (cmake -P): pcl_selective_seg_selective_loop's exit codes and messages on
# help, usage errors and an output folder that cannot be made, and that a failed run
# leaves its output folder as it was (the last cases simulate the cube with one round:
# about 2 s).
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
expect(2 "Give -out FOLDER")
expect(2 "Unknown argument '-bogus'" -bogus 1)
expect(2 "Missing value of '-out'" -out)
expect(2 "Give -out FOLDER" -scenes cube)
expect(2 "Unknown scene 'sofa'" -out ${BLOCKED}.d -scenes sofa)
expect(2 "Scene 'cube' is listed twice" -out ${BLOCKED}.d -scenes cube,cube)
# The loop sets the regions' budget; these were once accepted and still applied.
expect(2 "-roi_max_regions does not apply here" -out ${BLOCKED}.d -roi_max_regions 2)
expect(2 "-roi_max_sr does not apply here" -out ${BLOCKED}.d -roi_max_sr 1e-5)
# The loop sets the yield and the step too: these changed nothing but the windows'
# files, which recorded them as if they had been used.
expect(2 "-roi_yield does not apply here" -out ${BLOCKED}.d -roi_yield 0.5)
expect(2 "-roi_step_deg does not apply here" -out ${BLOCKED}.d -roi_step_deg 0.01)
expect(2 "-roi_refine does not apply here" -out ${BLOCKED}.d -roi_refine 10)
expect(2 "-roi_max_window_deg applies only with -window_steps 0"
  -out ${BLOCKED}.d -roi_max_window_deg 0.1)
# Out of range before any scan (these failed only after the uniform scans, exit 1),
# each message naming its option (one message listed all nine ranges).
expect(2 "Option -coarse_factor needs a value in \\[1, 100\\]"
  -out ${BLOCKED}.d -coarse_factor 1e300)
expect(2 "Option -window_steps needs 0 or a value in" -out ${BLOCKED}.d -window_steps 1e-12)
expect(2 "Option -iterations needs a whole number in \\[0, 100\\]"
  -out ${BLOCKED}.d -iterations 101)
# A negative seed was taken as "not given": the scene's own seed, without a word.
expect(2 "Option -seed needs a whole number" -out ${BLOCKED}.d -seed -5)
# -step_scale: 0.1 took minutes and GBs, 0.045 would take about 12 GB.
expect(2 "Option -step_scale needs a value in \\[0.25, 100\\]"
  -out ${BLOCKED}.d -step_scale 0.1)
expect(2 "ends with a comma" -out ${BLOCKED}.d -scenes cube,)
# A budget that cannot hold the coarse scan, whatever the scene, is refused before any
# scan, with a fraction that works, or, when none does, a coarser coarse scan.
expect(2 "give -coarse_factor 1.12 or more" -out ${BLOCKED}.d -coarse_factor 1)
# A repeated option (the first value was used silently).
expect(2 "Option -iterations is given more than once"
  -out ${BLOCKED}/out -iterations 1 -iterations 2 -scenes cube)
expect(1 "Cannot make the output folder '.*': .*writable folder"
  -out ${BLOCKED}/out -scenes cube)
expect(1 "Cannot make the output folder" -out ${BLOCKED} -scenes cube)

# contents(<variable> <folder>): the names in the folder, sorted
function(contents var folder)
  file(GLOB names RELATIVE ${folder} ${folder}/*)
  list(SORT names)
  set(${var} "${names}" PARENT_SCOPE)
endfunction()
# expectFullUnchanged(): WORK/full holds only what the test put there, cube.dat unchanged
macro(expectFullUnchanged)
  contents(left ${WORK}/full)
  file(READ ${WORK}/full/cube.dat cube_dat)
  if(NOT left STREQUAL "chair.dat;cube.dat" OR NOT cube_dat STREQUAL "old\n")
    set(failures "${failures}\n  a failed run changed its folder: '${left}', cube.dat "
      "'${cube_dat}'")
  endif()
endmacro()
# Failed runs leave the output folder as it was: no partial outputs, no temporaries, old
# files unchanged. Every file is staged and put in place at the end of the run; here
# the door fails after the cube's files were all staged: with -coarse_factor 1 its
# coarse scan is another draw at the finest uniform scan's step, and in this draw (the
# scenes' own seeds) it holds 86,379 points against that scan's 86,108, more than a
# budget of all of them (about 10 s).
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/full/chair.dat)
file(WRITE ${WORK}/full/cube.dat "old\n")
expect(1 "coarse scan's [0-9]+ points exceed the point budget"
  -out ${WORK}/full -scenes cube,door -iterations 1 -coarse_factor 1
  -budget_fraction 1)
expectFullUnchanged()
# An output that cannot be written (chair.dat is a folder) is refused before any scan.
expect(1 "cannot write '.*chair.dat': it is a folder"
  -out ${WORK}/full -scenes cube,chair -iterations 1)
expectFullUnchanged()
# Every output is checked before the scans: a folder in table.md's place (found only
# after the whole run before).
file(MAKE_DIRECTORY ${WORK}/probe/table.md)
expect(1 "cannot write '.*table.md': it is a folder" -out ${WORK}/probe -scenes cube)
contents(left ${WORK}/probe)
if(NOT left STREQUAL "table.md")
  set(failures "${failures}\n  the output probe left '${left}'")
endif()
# A run that fails after making its folder removes it (and its parent): here a step so
# coarse that a uniform scan has too few points; the message names -step_scale.
set(fresh ${WORK}/fresh/out)
expect(1 "the uniform scan at .* failed.*-step_scale 100"
  -out ${fresh} -scenes cube -iterations 1 -step_scale 100)
if(EXISTS ${WORK}/fresh)
  set(failures "${failures}\n  a failed run left the folder it made")
endif()
# A budget fraction too small for the coarse scan (which the budget includes): the
# message gives a fraction that works, and that fraction then runs.
expect(2 "-budget_fraction 1e-300 is less than the coarse scan's share .*: give -budget_fraction [0-9.e+-]+ or more"
  -out ${fresh} -scenes cube -iterations 1 -budget_fraction 1e-300)
expect(2 "-budget_fraction 0.05 is less than the coarse scan's share"
  -out ${fresh} -scenes cube -iterations 1 -budget_fraction 0.05)
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
# The windows' files record the budget the loop used (they said 0 points, step 0: the
# command line's values, which the loop replaces), here the cube's fine step 3.6 mrad.
file(READ ${fresh}/cube_windows.json windows_json)
file(READ ${fresh}/cube_coarse_rois.json coarse_json)
if(NOT windows_json MATCHES "\"max_points\": [1-9][0-9]*, [^\n]*\"target_step_rad\": 0.0036,"
   OR NOT coarse_json MATCHES "\"max_points\": [1-9][0-9]*, [^\n]*\"target_step_rad\": 0.00[0-9]+,")
  set(failures "${failures}\n  the windows' files do not record the loop's budget")
endif()
file(REMOVE_RECURSE ${WORK})

if(failures)
  message(FATAL_ERROR "unexpected exit codes or messages:${failures}")
endif()
