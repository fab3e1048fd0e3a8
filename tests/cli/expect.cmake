# Runs one command line and checks what a user would see: the exit code, a message pattern on
# stderr (and optionally one on stdout), and (optionally) that no output file was left behind.
#   cmake -DCMD="a;b;c" -DEXIT=2 -DPATTERN=regex [-DSTDOUT_PATTERN=regex] [-DNO_FILE=path]
#         [-DWORKDIR=dir] -P expect.cmake
if(NO_FILE)
  file(REMOVE "${NO_FILE}")
endif()
execute_process(COMMAND ${CMD} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err
                WORKING_DIRECTORY "${WORKDIR}")
if(NOT code EQUAL EXIT)
  message(FATAL_ERROR "exit code ${code}, expected ${EXIT}\nstdout: ${out}\nstderr: ${err}")
endif()
if(PATTERN AND NOT err MATCHES "${PATTERN}")
  message(FATAL_ERROR "stderr does not match '${PATTERN}':\n${err}")
endif()
if(STDOUT_PATTERN AND NOT out MATCHES "${STDOUT_PATTERN}")
  message(FATAL_ERROR "stdout does not match '${STDOUT_PATTERN}':\n${out}")
endif()
string(REGEX MATCHALL "\n" lines "${err}")
list(LENGTH lines nlines)
if(EXIT EQUAL 2 AND nlines GREATER 1)
  message(FATAL_ERROR "expected one line of error, got ${nlines}:\n${err}")
endif()
if(NO_FILE AND EXISTS "${NO_FILE}")
  message(FATAL_ERROR "the command left ${NO_FILE} behind")
endif()
