# ctest: the independent Embree tracer (bench/embree_tracer.cpp) renders a reference scene as
# exact mode does; its timings (bench/embree_tracer.py) mean something only then.
#   cmake -DTRACER=path -DLATTICE=path -DSCENE=path -DGEOMETRY=user|native -DMIN_PSNR=dB
#         -DWORK=dir -P embree_tracer_check.cmake
file(MAKE_DIRECTORY "${WORK}")
function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "${ARGV}: exit code ${code}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()
run(${TRACER} ${SCENE} -o ${WORK}/tracer-${GEOMETRY}.png --geometry ${GEOMETRY} --threads 2)
run(${LATTICE} render -q ${SCENE} -o ${WORK}/exact.png --mode exact --threads 2)
run(${LATTICE} compare ${WORK}/tracer-${GEOMETRY}.png ${WORK}/exact.png --json)
string(JSON psnr GET "${out}" psnr_db)
if(NOT psnr STREQUAL "inf" AND psnr LESS MIN_PSNR)
  message(FATAL_ERROR "${GEOMETRY}: ${psnr} dB against exact mode, below ${MIN_PSNR}")
endif()
message(STATUS "${GEOMETRY}: ${psnr} dB against exact mode")
