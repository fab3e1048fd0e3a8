# The complexity benchmark's scenes (bench/complexity_scenes.py) load and render: every one in
# exact mode at 16 x 16, and four in lattice mode with point-sampled tables (they fit their
# boxes and build in about a second; the big tufts' tables take a minute, so only `make bench`
# builds them; csg12's coverage tables, for the default filter, over a minute: one part, no
# capsule to cull pairs by).
#   cmake -DLATTICE=path -DPYTHON=python3 -DGEN=bench/complexity_scenes.py -DWORK=dir -P complexity_scenes.cmake
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "${ARGN}\nexit code ${code}\n${out}\n${err}")
  endif()
endfunction()

file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/cache)
run(${PYTHON} ${GEN} ${WORK} --size 16)
file(GLOB scenes ${WORK}/*.json)
list(LENGTH scenes n)
if(NOT n EQUAL 9)
  message(FATAL_ERROR "expected 9 scenes, the generator wrote ${n}: ${scenes}")
endif()
foreach(scene ${scenes})
  get_filename_component(name ${scene} NAME_WE)
  run(${LATTICE} render -q ${scene} -o ${WORK}/${name}.png)
endforeach()
foreach(name tuft200 csg12 ball-csg7 ball-tuft216)
  run(${LATTICE} render -q ${WORK}/${name}.json -o ${WORK}/${name}-lattice.png --mode lattice
      --filter none --lattice-dir ${WORK}/cache)
endforeach()
