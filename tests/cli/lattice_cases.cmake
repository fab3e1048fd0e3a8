# Lattice-table scenarios that need files prepared first; -DCASE=... picks one.
#   cmake -DLATTICE=path/to/lattice -DEXAMPLES=dir -DWORK=dir -DCASE=name -P lattice_cases.cmake
include(${CMAKE_CURRENT_LIST_DIR}/run.cmake)

file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(P2 ${EXAMPLES}/plate2-thistle.json)
set(P3 ${EXAMPLES}/plate3-hair-closeup.json)
set(LIMITS ${DATA}/limits)

if(CASE STREQUAL "corrupt")
  run(0 "" ${LATTICE} rasterize -q ${P3} --primitive hair --lattice-dir ${WORK})
  file(GLOB tables ${WORK}/hair-*.lht)
  # Overwrite one byte of the payload in place.
  execute_process(COMMAND sh -c "printf Z | dd of='${tables}' bs=1 seek=300 conv=notrunc 2>/dev/null")
  run(2 "hair-s1-hash14-[0-9a-f]+\\.lht: not a valid lattice table: payload checksum mismatch"
      ${LATTICE} render -q ${P3} --mode lattice --filter none --lattice-dir ${WORK} -o ${WORK}/x.png)
  if(EXISTS ${WORK}/x.png)
    message(FATAL_ERROR "an image was written")
  endif()
elseif(CASE STREQUAL "truncated")
  run(0 "" ${LATTICE} rasterize -q ${P3} --primitive hair --lattice-dir ${WORK})
  file(GLOB tables ${WORK}/hair-*.lht)
  file(SIZE ${tables} size)
  math(EXPR keep "${size} - 1000")
  execute_process(COMMAND truncate -s ${keep} ${tables})
  run(2 "not a valid lattice table: file holds [0-9]+ bytes after the header, header says [0-9]+ \\(truncated\\?\\)"
      ${LATTICE} render -q ${P3} --mode lattice --filter none --lattice-dir ${WORK} -o ${WORK}/x.png)
elseif(CASE STREQUAL "other_primitive")
  # The hair's cache file replaced by the thistle spike's table.
  run(0 "" ${LATTICE} rasterize -q ${P3} --primitive hair --lattice-dir ${WORK})
  file(GLOB hair ${WORK}/hair-*.lht)
  run(0 "" ${LATTICE} rasterize -q ${P2} --primitive spike -o ${hair})
  run(2 "lattice table is for hash14, 1 x 1 x 20 cells \\(sigma 1, sigma\\^-1 1\\), expected hash14, 7 x 7 x 20 cells"
      ${LATTICE} render -q ${P3} --mode lattice --filter none --lattice-dir ${WORK} -o ${WORK}/x.png)
elseif(CASE STREQUAL "missing_dir")
  # A missing cache directory is created, parents and all.
  run(0 ""
      ${LATTICE} render -q ${P3} --mode lattice --lattice-dir ${WORK}/no/such/dir -o ${WORK}/x.png)
  if(NOT IS_DIRECTORY ${WORK}/no/such/dir)
    message(FATAL_ERROR "the cache directory was not created")
  endif()
elseif(CASE STREQUAL "not_a_dir")
  file(WRITE ${WORK}/file "x")
  run(2 "file: lattice cache is not a directory"
      ${LATTICE} render -q ${P3} --mode lattice --lattice-dir ${WORK}/file -o ${WORK}/x.png)
elseif(CASE STREQUAL "too_big")
  run(2 "primitives\\.hair: the hash14 table of primitive 'hair' at 7000 x 7000 x 20000 cells \\(sigma\\^-1 = 1000\\) would need (about|at least) [0-9.]+ [kMGTPE]B"
      ${LATTICE} rasterize -q ${P3} --primitive hair --sigma-inv 1000 -o ${WORK}/big.lht)
  if(EXISTS ${WORK}/big.lht)
    message(FATAL_ERROR "a table was written")
  endif()
elseif(CASE STREQUAL "unknown_primitive")
  run(2 "no primitive named 'fur' \\(it has: hair\\)"
      ${LATTICE} rasterize -q ${P3} --primitive fur -o ${WORK}/t.lht)
elseif(CASE STREQUAL "candidates_any_parts")
  # candidates has no part limit: a 79-part chain renders as in exact mode.
  run(0 "" ${LATTICE} rasterize -q ${LIMITS}/long-chain.json --primitive chain --encoding candidates -o ${WORK}/t.lht)
  run(0 "" ${LATTICE} render -q ${LIMITS}/long-chain.json --mode lattice --encoding candidates --lattice-dir ${WORK} -o ${WORK}/a.png)
  run(0 "" ${LATTICE} render -q ${LIMITS}/long-chain.json -o ${WORK}/b.png)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/a.png ${WORK}/b.png RESULT_VARIABLE same)
  if(NOT same EQUAL 0)
    message(FATAL_ERROR "candidates image of the 79-part chain differs from exact mode's")
  endif()
elseif(CASE STREQUAL "sigma_inv_range")
  foreach(k 0 -3 1025)
    run(2 "^lattice: error: --sigma-inv: sigma\\^-1 = ${k} is out of range \\(1 to 1024\\)\n$"
        ${LATTICE} rasterize -q ${P3} --primitive hair --sigma-inv ${k} -o ${WORK}/t.lht)
  endforeach()
  run(2 "--sigma-inv: sigma\\^-1 = 0 is out of range"
      ${LATTICE} render -q ${P3} --mode lattice --sigma-inv 0 --lattice-dir ${WORK} -o ${WORK}/x.png)
elseif(CASE STREQUAL "filter")
  # Filtered lattices: the coverage table is built and used; smooth is the default, and
  # --filter none is the plain lattice, as is an encoding without coverage asked for alone.
  run(0 "" ${LATTICE} render -q ${P3} --mode lattice --filter smooth --lod off --lattice-dir ${WORK}
      -o ${WORK}/smooth.png --stats ${WORK}/s.json)
  file(READ ${WORK}/s.json stats)
  if(NOT stats MATCHES "\"filter\": *\"smooth\"" OR NOT stats MATCHES "\"encoding\": *\"coverage\"")
    message(FATAL_ERROR "stats do not name the filter and its encoding:\n${stats}")
  endif()
  file(GLOB tables ${WORK}/hair-s1-coverage-*.lht)
  if(NOT tables)
    message(FATAL_ERROR "no coverage table in the cache")
  endif()
  run(0 "" ${LATTICE} render -q ${P3} --mode lattice --filter none --lattice-dir ${WORK} -o ${WORK}/none.png)
  run(0 "" ${LATTICE} render -q ${P3} --mode lattice --encoding hash14 --lattice-dir ${WORK} -o ${WORK}/plain.png)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/none.png ${WORK}/plain.png RESULT_VARIABLE differ)
  if(differ)
    message(FATAL_ERROR "--filter none differs from the plain lattice image")
  endif()
  run(0 "" ${LATTICE} render -q ${P3} --mode lattice --lod off --lattice-dir ${WORK} -o ${WORK}/default.png)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/smooth.png ${WORK}/default.png RESULT_VARIABLE differ)
  if(differ)
    message(FATAL_ERROR "the default filter is not smooth")
  endif()
  execute_process(COMMAND ${LATTICE} inspect ${tables} --no-certify OUTPUT_VARIABLE out RESULT_VARIABLE code)
  if(NOT code EQUAL 0 OR NOT out MATCHES "partly covered")
    message(FATAL_ERROR "inspect does not report coverage:\n${out}")
  endif()
elseif(CASE STREQUAL "filter_errors")
  run(2 "--filter: smoothest not in \\{box,none,smooth\\}"
      ${LATTICE} render -q ${P3} --mode lattice --filter smoothest --lattice-dir ${WORK} -o ${WORK}/x.png)
  run(2 "--lod: maybe not in"
      ${LATTICE} render -q ${P3} --mode lattice --filter box --lod maybe --lattice-dir ${WORK} -o ${WORK}/x.png)
  run(2 "^lattice: error: --filter: filtered lattices need a table encoding that stores coverage \\(--encoding coverage\\), not 'hash14'\n$"
      ${LATTICE} render -q ${P3} --mode lattice --filter box --encoding hash14 --lattice-dir ${WORK} -o ${WORK}/x.png)
  if(EXISTS ${WORK}/x.png)
    message(FATAL_ERROR "an image was written")
  endif()
elseif(CASE STREQUAL "unknown_encoding")
  run(2 "--encoding: unknown table encoding 'nope' \\(known: hash14, dense, candidates, perfect5, perfect6, perfect7, learned, coverage\\)"
      ${LATTICE} rasterize -q ${P3} --primitive hair --encoding nope -o ${WORK}/t.lht)
elseif(CASE STREQUAL "point_limit")
  run(2 "primitives\\.hair: the hash14 encoding keys at most 65535 boundary points; a lattice of 84 x 84 x 240 cells \\(sigma\\^-1 = 12\\) has 94754"
      ${LATTICE} rasterize -q ${P3} --primitive hair --sigma-inv 12 -o ${WORK}/t.lht)
elseif(CASE STREQUAL "outside_box")
  run(2 "outside-box\\.json: primitives\\.blob: primitive 'blob' reaches outside its lattice box \\[0, 1\\] x \\[0, 1\\] x \\[0, 1\\]"
      ${LATTICE} rasterize -q ${LIMITS}/outside-box.json --primitive blob -o ${WORK}/t.lht)
elseif(CASE STREQUAL "tilted_tori_fit")
  # Tori tilted in every direction, major 3 + minor 0.35 about the centre of an 8^3 box: their
  # exact extents fit, where the box around each transformed torus box did not.
  run(0 "" ${LATTICE} rasterize -q ${LIMITS}/tilted-tori.json --primitive rings -o ${WORK}/t.lht)
elseif(CASE STREQUAL "render_then_reuse")
  # A lattice render builds its table once, then finds it in the cache.
  run(0 "1 table .*1 built" ${LATTICE} render ${P3} --mode lattice --filter none --lattice-dir ${WORK} -o ${WORK}/a.png)
  run(0 "1 table .*0 built" ${LATTICE} render ${P3} --mode lattice --filter none --lattice-dir ${WORK} -o ${WORK}/b.png)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/a.png ${WORK}/b.png RESULT_VARIABLE same)
  if(NOT same EQUAL 0)
    message(FATAL_ERROR "the cached table renders a different image")
  endif()
else()
  message(FATAL_ERROR "unknown case ${CASE}")
endif()
