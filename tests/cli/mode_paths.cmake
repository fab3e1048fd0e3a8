# Every default command-line path of `render` against an exact many-sample truth: exact mode
# (1 and 4 spp), exact mode with footprint filtering, lattice mode (tables, cold cache) and auto
# mode, on a fuzzy ball whose hairs are about a pixel wide. Each path must reach its PSNR floor
# and say what answered (--stats); a bald ball (the hairs lost) and point samples where a
# filtered path should be must fall below the floors, so that a broken path fails.
#   cmake -DLATTICE=path -DSCENE=fuzzy-ball.json -DWORK=dir -P mode_paths.cmake
include(${CMAKE_CURRENT_LIST_DIR}/run.cmake)

file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/cache)

# The PSNR (dB) of image against truth, from `lattice compare --json`.
function(psnr_of image truth out)
  execute_process(COMMAND ${LATTICE} compare ${image} ${truth} --json
                  RESULT_VARIABLE code OUTPUT_VARIABLE json ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "compare ${image}: exit code ${code}\n${err}")
  endif()
  string(JSON db GET "${json}" psnr_db)
  set(${out} ${db} PARENT_SCOPE)
endfunction()

# Renders with the given arguments into NAME.png (and NAME.json stats) and checks its PSNR
# against the truth is at least FLOOR.
function(expect_path name floor)
  run(0 "" ${LATTICE} render -q ${SCENE} -o ${WORK}/${name}.png --stats ${WORK}/${name}.json
      --lattice-dir ${WORK}/cache ${ARGN})
  psnr_of(${WORK}/${name}.png ${WORK}/truth.png db)
  message(STATUS "${name}: ${db} dB (floor ${floor})")
  if(db LESS floor)
    message(FATAL_ERROR "${name} (${ARGN}): ${db} dB against the truth, below ${floor}")
  endif()
endfunction()

# The stats' first primitive was answered by `by`; with_visits: table visits above 0.
function(expect_answer name by with_visits)
  file(READ ${WORK}/${name}.json stats)
  string(JSON answered GET "${stats}" primitives 0 answered_by)
  if(NOT answered STREQUAL by)
    message(FATAL_ERROR "${name}: answered by '${answered}', expected '${by}'\n${stats}")
  endif()
  string(JSON visits GET "${stats}" table_visits)
  if(with_visits AND NOT visits GREATER 0)
    message(FATAL_ERROR "${name}: no table visits\n${stats}")
  elseif(NOT with_visits AND NOT visits EQUAL 0)
    message(FATAL_ERROR "${name}: ${visits} table visits where no table should be read")
  endif()
endfunction()

run(0 "" ${LATTICE} render -q ${SCENE} -o ${WORK}/truth.png --spp 64)

# Floors about 1 dB under what each path measured (64 x 64, truth at 64 spp).
set(EXACT_FLOOR 22)
set(FILTERED_FLOOR 29.5)
expect_path(exact ${EXACT_FLOOR} --mode exact)
expect_path(exact4 28 --mode exact --spp 4)
expect_path(footprint ${FILTERED_FLOOR} --mode exact --footprint on)
expect_answer(footprint "sub-rays" FALSE)
expect_path(lattice 29 --mode lattice)
expect_answer(lattice "filtered tables" TRUE)
expect_path(auto ${FILTERED_FLOOR} --mode auto)
expect_answer(auto "sub-rays" FALSE)
expect_path(lattice_none 20 --mode lattice --filter none)
expect_answer(lattice_none "table" TRUE)

# The floors catch broken paths: point samples where a filter should be, and hairs lost.
psnr_of(${WORK}/exact.png ${WORK}/truth.png point_db)
if(NOT point_db LESS FILTERED_FLOOR)
  message(FATAL_ERROR "point samples (${point_db} dB) pass the filtered paths' floor")
endif()
file(READ ${SCENE} scene)
string(JSON count LENGTH "${scene}" objects)
math(EXPR last "${count} - 1")
string(JSON scatter_type GET "${scene}" objects ${last} type)
if(NOT scatter_type STREQUAL "scatter")
  message(FATAL_ERROR "the scene's last object should be its fur (a scatter)")
endif()
string(JSON bald REMOVE "${scene}" objects ${last})
file(WRITE ${WORK}/bald.json "${bald}")
run(0 "" ${LATTICE} render -q ${WORK}/bald.json -o ${WORK}/bald.png)
psnr_of(${WORK}/bald.png ${WORK}/truth.png bald_db)
if(NOT bald_db LESS 20)
  message(FATAL_ERROR "a bald ball (${bald_db} dB) passes the lowest floor")
endif()
