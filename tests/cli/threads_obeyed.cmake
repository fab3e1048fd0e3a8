# Fails unless the render stats in STATS say THREADS threads rendered.
#   cmake -DSTATS=file.json -DTHREADS=n -P threads_obeyed.cmake
file(READ ${STATS} stats)
string(JSON threads GET "${stats}" threads)
if(NOT threads EQUAL THREADS)
  message(FATAL_ERROR "${STATS}: rendered on ${threads} threads, --threads ${THREADS} asked for")
endif()
