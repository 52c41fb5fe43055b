# ctest driver (cmake -P): pcl_selective_seg_selective_loop's exit codes and messages on
# help, usage errors and an output folder that cannot be made. None of these cases
# simulates a scan.
#   -DLOOP=<the loop tool> -DBLOCKED=<a regular file: no folder can be made under it>
foreach(var LOOP BLOCKED)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "loop_tool_exit_codes.cmake: -D${var}=... is missing")
  endif()
endforeach()
file(WRITE ${BLOCKED} "not a folder\n")

set(failures "")
# expect(<exit code> <regex the error output must match, or ""> <argument>...)
function(expect code pattern)
  execute_process(COMMAND ${LOOP} ${ARGN}
    RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
  if(NOT rc EQUAL code)
    set(failures "${failures}\n  '${ARGN}': exit '${rc}', expected ${code} (${err})"
      PARENT_SCOPE)
  elseif(NOT pattern STREQUAL "" AND NOT err MATCHES "${pattern}")
    set(failures "${failures}\n  '${ARGN}': message '${err}' does not match '${pattern}'"
      PARENT_SCOPE)
  endif()
endfunction()

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
# A repeated option (the first value was used silently).
expect(2 "Option -iterations is given more than once"
  -out ${BLOCKED}/out -iterations 1 -iterations 2 -scenes cube)
expect(1 "Cannot make the output folder '.*': .*writable folder"
  -out ${BLOCKED}/out -scenes cube)
expect(1 "Cannot make the output folder" -out ${BLOCKED} -scenes cube)

if(failures)
  message(FATAL_ERROR "unexpected exit codes or messages:${failures}")
endif()
