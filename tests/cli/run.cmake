# run(EXPECTED_EXIT PATTERN COMMAND...): runs the command, fails unless it exits with
# EXPECTED_EXIT and (when PATTERN is not empty) its stderr matches PATTERN. Shared by the CLI
# scenario scripts.
function(run expect_code pattern)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL expect_code)
    message(FATAL_ERROR "${ARGN}\nexit code ${code}, expected ${expect_code}\n${out}\n${err}")
  endif()
  if(pattern AND NOT err MATCHES "${pattern}")
    message(FATAL_ERROR "${ARGN}\nstderr does not match '${pattern}':\n${err}")
  endif()
endfunction()
