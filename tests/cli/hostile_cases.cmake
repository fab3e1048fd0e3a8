# Hostile-input and interruption scenarios (issue 11) that need files generated or several
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
else()
  message(FATAL_ERROR "unknown case ${CASE}")
endif()
