# `lattice` under mpirun: two ranks give the same bytes as one process, and an input
# error on any rank ends the job at once with one message and exit code 2.
#   cmake -DLATTICE=path -DMPIEXEC=mpirun -DEXAMPLES=dir -DDATA=dir -DWORK=dir -DCASE=name -P mpi_cases.cmake
include(${CMAKE_CURRENT_LIST_DIR}/run.cmake)

file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(P3 ${EXAMPLES}/plate3-hair-closeup.json)
set(P4 ${EXAMPLES}/plate4-fuzzy-sphere-1000.json)
# -q: without it Open MPI adds its own banner when a rank exits with an error.
set(MPI2 ${MPIEXEC} -q -n 2 --oversubscribe)

function(same a b what)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${a} ${b} RESULT_VARIABLE differ)
  if(NOT differ EQUAL 0)
    message(FATAL_ERROR "${what}: 2 ranks and 1 process differ (${a}, ${b})")
  endif()
endfunction()

# run_timed(EXIT PATTERN SECONDS cmd...): like run(), and stderr is one line, within SECONDS.
function(run_timed expect_code pattern seconds)
  string(TIMESTAMP t0 "%s")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  string(TIMESTAMP t1 "%s")
  math(EXPR took "${t1} - ${t0}")
  if(NOT code EQUAL expect_code)
    message(FATAL_ERROR "${ARGN}\nexit code ${code}, expected ${expect_code}\n${out}\n${err}")
  endif()
  if(NOT err MATCHES "^lattice: error: ${pattern}[^\n]*\n$")
    message(FATAL_ERROR "${ARGN}\nexpected one line matching '${pattern}', got:\n${err}")
  endif()
  if(took GREATER seconds)
    message(FATAL_ERROR "${ARGN}\ntook ${took} s, more than ${seconds}")
  endif()
endfunction()

if(CASE STREQUAL "render_exact")
  # Radiance (PFM, floats) and display (PNG) pixels both travel; at 2 spp the random samplers
  # draw every sample from its pixel's seed.
  foreach(sampler sobol jitter)
    foreach(ext pfm png)
      run(0 "" ${LATTICE} render -q ${P4} --spp 2 --sampler ${sampler} -o ${WORK}/one.${ext})
      run(0 "" ${MPI2} ${LATTICE} render -q ${P4} --spp 2 --sampler ${sampler} -o ${WORK}/two.${ext})
      same(${WORK}/one.${ext} ${WORK}/two.${ext} "exact render (${sampler}, ${ext})")
    endforeach()
  endforeach()
  # 3 ranks x 2 threads: rank 0 deals to two askers; on an image of 3 tiles, fewer than the
  # job's 6 threads, some ranks' first chunks are empty (they must not be waited for).
  run(0 "" ${MPIEXEC} -q -n 3 --oversubscribe ${LATTICE} render -q ${P4} --spp 2 --sampler jitter --threads 2 -o ${WORK}/three.png)
  same(${WORK}/one.png ${WORK}/three.png "exact render (3 ranks)")
  file(READ ${P4} scene)
  string(JSON scene SET "${scene}" camera width 40)
  string(JSON scene SET "${scene}" camera height 16)
  file(WRITE ${WORK}/tiny.json "${scene}")
  run(0 "" ${LATTICE} render -q ${WORK}/tiny.json -o ${WORK}/tiny-one.png)
  run(0 "" ${MPIEXEC} -q -n 3 --oversubscribe ${LATTICE} render -q ${WORK}/tiny.json --threads 2 -o ${WORK}/tiny-three.png)
  same(${WORK}/tiny-one.png ${WORK}/tiny-three.png "exact render of 3 tiles (3 ranks)")
elseif(CASE STREQUAL "render_lattice")
  # The two ranks build the missing table together: the same table, the same image.
  file(MAKE_DIRECTORY ${WORK}/one ${WORK}/two)
  run(0 "" ${LATTICE} render -q ${P3} --mode lattice --filter none --lattice-dir ${WORK}/one -o ${WORK}/one.png)
  run(0 "1 built" ${MPI2} ${LATTICE} render ${P3} --mode lattice --filter none --lattice-dir ${WORK}/two -o ${WORK}/two.png)
  same(${WORK}/one.png ${WORK}/two.png "lattice render")
  file(GLOB one ${WORK}/one/*.lht)
  file(GLOB two ${WORK}/two/*.lht)
  same("${one}" "${two}" "table built while rendering")
  # And with the table already cached: loaded by both ranks, nothing built.
  run(0 "0 built" ${MPI2} ${LATTICE} render ${P3} --mode lattice --filter none --lattice-dir ${WORK}/two -o ${WORK}/again.png)
  same(${WORK}/one.png ${WORK}/again.png "lattice render from the cache")
elseif(CASE STREQUAL "rasterize")
  foreach(encoding hash14 dense candidates)
    run(0 "" ${LATTICE} rasterize -q ${P3} --primitive hair --sigma-inv 2 --encoding ${encoding} -o ${WORK}/one.lht)
    run(0 "" ${MPI2} ${LATTICE} rasterize -q ${P3} --primitive hair --sigma-inv 2 --encoding ${encoding}
        -o ${WORK}/two.lht --stats ${WORK}/two.json)
    same(${WORK}/one.lht ${WORK}/two.lht "rasterize (${encoding})")
  endforeach()
  file(READ ${WORK}/two.json stats)
  string(JSON nranks LENGTH "${stats}" ranks)
  if(NOT nranks EQUAL 2)
    message(FATAL_ERROR "rasterize --stats has ${nranks} ranks, expected 2:\n${stats}")
  endif()
elseif(CASE STREQUAL "rank0_modes")
  # Modes that are not dealt across ranks render on rank 0 alone, to the same bytes.
  foreach(mode texture particles)
    run(0 "" ${LATTICE} render -q ${DATA}/bad/furred-sphere.json --spp 4 --mode ${mode} -o ${WORK}/one-${mode}.png)
    run(0 "" ${MPI2} ${LATTICE} render -q ${DATA}/bad/furred-sphere.json --spp 4 --mode ${mode} -o ${WORK}/two-${mode}.png)
    same(${WORK}/one-${mode}.png ${WORK}/two-${mode}.png "${mode} mode")
  endforeach()
elseif(CASE STREQUAL "errors")
  # The same mistake on every rank: said once, by rank 0.
  run_timed(2 "[^\n]*syntax-error.json:87:[0-9]+: invalid JSON" 30
            ${MPI2} ${LATTICE} render ${DATA}/bad/syntax-error.json -o ${WORK}/x.png)
  # Every rank runs the same command line, but in its own directory (`A : B` with --wdir), as
  # nodes that hold their own copies of the files would.
  file(MAKE_DIRECTORY ${WORK}/r0/cache ${WORK}/r1/cache)
  set(SAME_LINE_TWO_DIRS ${MPIEXEC} -q --oversubscribe -n 1 --wdir ${WORK}/r0 ${LATTICE} RENDER
                         : -n 1 --wdir ${WORK}/r1 ${LATTICE} RENDER)
  # A mistake in rank 1's copy of the scene only: said once, naming the rank.
  configure_file(${P4} ${WORK}/r0/scene.json COPYONLY)
  configure_file(${DATA}/bad/singular-transform.json ${WORK}/r1/scene.json COPYONLY)
  string(REPLACE "RENDER" "render;scene.json;-o;${WORK}/y.png" cmd "${SAME_LINE_TWO_DIRS}")
  run_timed(2 "scene.json: objects\\[2\\]\\.transform: matrix is singular.*\\(on rank 1 of 2, host [^)]+\\)" 30 ${cmd})
  # Two good but different copies: refused, not a patchwork image.
  configure_file(${DATA}/bad/good.json ${WORK}/r1/scene.json COPYONLY)
  run_timed(2 "scene.json: the scene file differs between rank 0 and rank 1" 30 ${cmd})
  # A table cache that rank 1 does not share with rank 0: it cannot find the table rank 0 built.
  configure_file(${P3} ${WORK}/r0/scene.json COPYONLY)
  configure_file(${P3} ${WORK}/r1/scene.json COPYONLY)
  string(REPLACE "RENDER" "render;scene.json;--mode;lattice;--filter;none;--lattice-dir;cache;-o;${WORK}/z.png" cmd "${SAME_LINE_TWO_DIRS}")
  run_timed(2 "[^\n]*cannot open lattice table.*every rank shares.*\\(on rank 1 of 2" 60 ${cmd})
  # Different command lines (MPMD): refused.
  run_timed(2 "the command line differs between rank 0 and rank 1" 30
            ${MPIEXEC} -q --oversubscribe -n 1 ${LATTICE} render ${P4} -o ${WORK}/w.png
            : -n 1 ${LATTICE} render ${P4} --spp 2 -o ${WORK}/w.png)
  # Usage errors too.
  run_timed(2 "--spp" 30 ${MPI2} ${LATTICE} render --spp 0 ${P4} -o ${WORK}/u.png)
  foreach(f x.png y.png z.png w.png u.png)
    if(EXISTS ${WORK}/${f})
      message(FATAL_ERROR "a failed job wrote ${f}")
    endif()
  endforeach()
else()
  message(FATAL_ERROR "unknown case ${CASE}")
endif()
