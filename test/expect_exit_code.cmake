# Included by the ctest drivers (cmake -P) that check a tool's exit codes and messages.
# expect(<exit code> <regex the error output must match, or ""> <argument>...) runs
# ${TOOL} with the arguments (for at most 120 s: a tool waiting on a FIFO fails instead
# of hanging) and adds any mismatch to the variable `failures`.
function(expect code pattern)
  execute_process(COMMAND ${TOOL} ${ARGN}
    RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err TIMEOUT 120)
  if(NOT rc EQUAL code)
    set(failures "${failures}\n  '${ARGN}': exit '${rc}', expected ${code} (${err})"
      PARENT_SCOPE)
  elseif(NOT pattern STREQUAL "" AND NOT err MATCHES "${pattern}")
    set(failures "${failures}\n  '${ARGN}': message '${err}' does not match '${pattern}'"
      PARENT_SCOPE)
  endif()
endfunction()
