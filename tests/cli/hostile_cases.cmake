# Hostile-input and interruption scenarios that need files generated or several
# processes; -DCASE=... picks one.
#   cmake -DLATTICE=path/to/lattice -DDATA=tests/data/bad -DWORK=dir -DCASE=name -P hostile_cases.cmake
include(${CMAKE_CURRENT_LIST_DIR}/run.cmake)

# Fails if anything but the listed names is in WORK (e.g. a *.tmp-* left behind).
function(expect_only)
  file(GLOB left RELATIVE ${WORK} ${WORK}/*)
  list(REMOVE_ITEM left ${ARGN} "")
  if(left)
    message(FATAL_ERROR "left behind in ${WORK}: ${left}")
  endif()
endfunction()

# A scene with one CSG union nested `depth` levels deep around a sphere.
function(write_nested_csg path depth)
  string(REPEAT "{\"type\": \"csg\", \"op\": \"union\", \"children\": [" ${depth} open)
  string(REPEAT "]}" ${depth} close)
  file(WRITE ${path} "{\"camera\": {\"eye\": [0, -10, 3], \"look_at\": [0, 0, 0], "
       "\"fov_y_deg\": 40, \"width\": 16, \"height\": 16},\n"
       "\"materials\": {\"red\": {}},\n\"objects\": [{\"type\": \"csg\", \"op\": \"union\", "
       "\"material\": \"red\", \"children\": [${open}{\"type\": \"sphere\", \"radius\": 1}${close}]}]}\n")
endfunction()

file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

if(CASE STREQUAL "deep_csg")
  # 3,000 levels overflowed the stack under ASan, 100,000 in any build.
  write_nested_csg(${WORK}/deep300.json 300)
  run(2 "deep300.json: objects\\[0\\](\\.children\\[0\\])+: csg tree nested deeper than 256 levels"
      ${LATTICE} render -q ${WORK}/deep300.json -o ${WORK}/x.png)
  write_nested_csg(${WORK}/deep100k.json 100000)
  run(2 "deep100k.json:3:[0-9]+: invalid JSON: nested deeper than 1024 levels"
      ${LATTICE} render -q ${WORK}/deep100k.json -o ${WORK}/x.png)
  expect_only(deep300.json deep100k.json)
elseif(CASE STREQUAL "concurrent_stats")
  # Renders sharing --stats (and the output) all succeed: the temporaries never collide.
  foreach(round RANGE 1 3)
    set(cmds "")
    foreach(i RANGE 1 4)
      list(APPEND cmds COMMAND ${LATTICE} render -q ${DATA}/good.json -o ${WORK}/out.png
           --stats ${WORK}/stats.json --threads 1)
    endforeach()
    execute_process(${cmds} RESULTS_VARIABLE codes ERROR_VARIABLE err)
    if(NOT codes STREQUAL "0;0;0;0")
      message(FATAL_ERROR "exit codes ${codes}\n${err}")
    endif()
  endforeach()
  expect_only(out.png stats.json)
elseif(CASE STREQUAL "sigint")
  # A long render stopped by SIGINT (then SIGTERM): exit 130 (143), one message, no output and
  # no temporary left. The sleep lets it get past loading into the render.
  foreach(sig INT TERM)
    execute_process(COMMAND sh -c "'${LATTICE}' render -q '${DATA}/good.json' -o '${WORK}/x.png' \
                                   --stats '${WORK}/s.json' --spp 65536 --threads 1 & \
                                   pid=$!; sleep 2; kill -${sig} $pid; wait $pid"
                    RESULT_VARIABLE code ERROR_VARIABLE err)
    if(sig STREQUAL "INT")
      set(want 130)
      set(text interrupted)
    else()
      set(want 143)
      set(text terminated)
    endif()
    if(NOT code EQUAL want OR NOT err STREQUAL "lattice: ${text}\n")
      message(FATAL_ERROR "SIG${sig}: exit code ${code}, expected ${want}\n${err}")
    endif()
  endforeach()
  expect_only()
elseif(CASE STREQUAL "special_paths")
  # A FIFO, a device or a directory where a file is expected is refused before anything
  # blocks on it or reads without end: as the scene, a mesh, a PNG, a table.
  execute_process(COMMAND mkfifo ${WORK}/fifo.json ${WORK}/fifo.obj RESULT_VARIABLE made)
  if(NOT made EQUAL 0)
    message(FATAL_ERROR "mkfifo failed")
  endif()
  run(2 "fifo.json: cannot open scene file: it is a FIFO, not a regular file"
      ${LATTICE} render -q ${WORK}/fifo.json -o ${WORK}/x.png)
  run(2 "/dev/zero: cannot open scene file: it is a device, not a regular file"
      ${LATTICE} render -q /dev/zero -o ${WORK}/x.png)
  run(2 "fifo.json: cannot open PNG file: it is a FIFO" ${LATTICE} compare ${WORK}/fifo.json ${WORK}/fifo.json)
  run(2 "fifo.json: cannot open lattice table: it is a FIFO" ${LATTICE} inspect ${WORK}/fifo.json)
  foreach(mesh fifo.obj /dev/zero ${WORK})
    file(WRITE ${WORK}/scene.json "{\"camera\": {\"eye\": [0, -5, 0], \"look_at\": [0, 0, 0], "
         "\"fov_y_deg\": 30, \"width\": 8, \"height\": 8}, \"materials\": {\"a\": {}},\n"
         "\"objects\": [{\"type\": \"mesh\", \"file\": \"${mesh}\", \"material\": \"a\"}]}\n")
    run(2 "scene.json: objects\\[0\\]\\.file: .*: cannot open mesh file: it is a (FIFO|device|directory)"
        ${LATTICE} render -q ${WORK}/scene.json -o ${WORK}/x.png)
  endforeach()
  # An OBJ's material files are never opened: a FIFO named by mtllib is no matter.
  file(WRITE ${WORK}/tri.obj "mtllib fifo.obj\nusemtl x\nv 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n")
  file(READ ${WORK}/scene.json text)
  string(REPLACE "${WORK}" "tri.obj" text "${text}")
  file(WRITE ${WORK}/scene.json "${text}")
  run(0 "" ${LATTICE} render -q ${WORK}/scene.json -o ${WORK}/x.png)
elseif(CASE STREQUAL "scatter_bare_output")
  # `lattice scatter SCENE -o placed.json`, a bare name in the working directory, with a mesh in
  # the scene: the mesh path is rewritten relative to the output and the result renders.
  execute_process(COMMAND ${LATTICE} scatter ${DATA}/scatter-mesh-good.json -o placed.json
                  WORKING_DIRECTORY ${WORK} RESULT_VARIABLE code ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "scatter -o placed.json: exit code ${code}\n${err}")
  endif()
  run(0 "" ${LATTICE} render -q ${WORK}/placed.json -o ${WORK}/x.png)
  expect_only(placed.json x.png)
else()
  message(FATAL_ERROR "unknown case ${CASE}")
endif()
