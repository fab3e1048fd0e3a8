# Command-line tests: every class of bad input exits with 2, prints one message naming the file
# and the place, and writes no image. Also: 1 and 2 threads give identical bytes.
set(BAD ${CMAKE_CURRENT_SOURCE_DIR}/data/bad)
set(CLI_OUT ${CMAKE_CURRENT_BINARY_DIR}/cli-out)
file(MAKE_DIRECTORY ${CLI_OUT})

function(lattice_cli_error name scene pattern)
  add_test(NAME cli.${name}
    COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;${scene};-o;${CLI_OUT}/${name}.png"
            -DEXIT=2 "-DPATTERN=${pattern}" -DNO_FILE=${CLI_OUT}/${name}.png
            -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
endfunction()

lattice_cli_error(syntax_error ${BAD}/syntax-error.json "syntax-error.json:87:[0-9]+: invalid JSON")
lattice_cli_error(wrong_type ${BAD}/wrong-type.json "wrong-type.json: objects\\[0\\]\\.radius: expected a number, found a string")
lattice_cli_error(missing_field ${BAD}/missing-field.json "missing-field.json: objects\\[0\\]: missing field 'radius'")
lattice_cli_error(unknown_material ${BAD}/unknown-material.json "objects\\[0\\]\\.material: unknown material 'blue'")
lattice_cli_error(unknown_primitive ${BAD}/unknown-primitive.json "objects\\[2\\]\\.primitive: unknown primitive 'fur'")
lattice_cli_error(unknown_type ${BAD}/unknown-type.json "objects\\[0\\]\\.type: unknown object type 'blob'")
lattice_cli_error(singular_transform ${BAD}/singular-transform.json "objects\\[2\\]\\.transform: matrix is singular")
lattice_cli_error(negative_radius ${BAD}/negative-radius.json "objects\\[0\\]\\.radius: must be positive, found -2")
lattice_cli_error(bad_polynomial ${BAD}/bad-polynomial.json "objects\\[1\\]\\.polynomial: column 7: unexpected")
lattice_cli_error(degree_five ${BAD}/degree-five.json "objects\\[1\\]\\.polynomial: .*degree 5")
lattice_cli_error(missing_sphere ${BAD}/missing-sphere.json "primitives\\.hair\\.cylinders\\[0\\]\\[1\\]: sphere index 5 does not exist")
lattice_cli_error(impossible_size ${BAD}/impossible-size.json "camera\\.width: must be between 1 and 32768")
lattice_cli_error(missing_scene ${BAD}/no-such-file.json "no-such-file.json: cannot open scene file: No such file or directory")
# Hostile inputs: one located message, exit 2, never a crash or a huge allocation.
lattice_cli_error(huge_number ${BAD}/huge-number.json "huge-number.json:2:69: number 1e400 is out of the range of a double")
lattice_cli_error(overflowing_transform ${BAD}/overflowing-transform.json "objects\\[1\\]\\.transform: the transform overflows")
add_test(NAME cli.too_many_samples
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;--spp;256;${BAD}/too-many-samples.json;-o;${CLI_OUT}/spp.png"
          -DEXIT=2 "-DPATTERN=too-many-samples.json: camera: 8192 x 8192 pixels x 256 samples per pixel is over the limit of 4294967296 samples"
          -DNO_FILE=${CLI_OUT}/spp.png -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
add_test(NAME cli.extreme_quartic_renders
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;-q;${BAD}/extreme-quartic.json;-o;${CLI_OUT}/quartic.png"
          -DEXIT=0 -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
add_test(NAME cli.png_claiming_huge_size
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;compare;${BAD}/claims-20000x20000.png;${BAD}/claims-20000x20000.png"
          -DEXIT=2 "-DPATTERN=claims-20000x20000.png: PNG header claims 20000 x 20000 pixels, over the limit"
          -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
foreach(case deep_csg concurrent_stats sigint special_paths scatter_bare_output)
  add_test(NAME cli.hostile_${case}
    COMMAND ${CMAKE_COMMAND} -DLATTICE=$<TARGET_FILE:lattice> -DDATA=${BAD}
            -DWORK=${CLI_OUT}/hostile-${case} -DCASE=${case}
            -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/hostile_cases.cmake)
endforeach()

add_test(NAME cli.unwritable_output
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;${BAD}/good.json;-o;${CLI_OUT}/no/such/dir/x.png"
          -DEXIT=2 "-DPATTERN=no/such/dir/x.png: cannot write" -DWORKDIR=${CLI_OUT}
          -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
add_test(NAME cli.unknown_extension
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;${BAD}/good.json;-o;${CLI_OUT}/x.jpg"
          -DEXIT=2 "-DPATTERN=x.jpg: unsupported image format '.jpg'" -DNO_FILE=${CLI_OUT}/x.jpg
          -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
add_test(NAME cli.usage_error
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;--spp;0;${BAD}/good.json;-o;${CLI_OUT}/u.png"
          -DEXIT=2 "-DPATTERN=--spp" -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
add_test(NAME cli.sampler_refused
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;--sampler;halton;${BAD}/good.json;-o;${CLI_OUT}/sa.png"
          -DEXIT=2 "-DPATTERN=--sampler" -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
# The summary line names the sampler that ran: the one asked for, the default, the centre at 1 spp.
foreach(case "sobol|--sampler;sobol;--spp;4|4 spp .sobol." "default|--spp;4|4 spp .grid."
             "centre|--sampler;jitter|1 spp .centre.")
  string(REPLACE "|" ";" case "${case}")
  list(POP_FRONT case name)
  list(POP_BACK case pattern)
  add_test(NAME cli.sampler_reported_${name}
    COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;${case};${BAD}/good.json;-o;${CLI_OUT}/sr-${name}.png"
            -DEXIT=0 "-DPATTERN=${pattern}" -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
endforeach()
foreach(budget nan -1 inf 12x)
  add_test(NAME cli.lod_budget_refused_${budget}
    COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;--mode;lattice;--lod-budget;${budget};${BAD}/good.json;-o;${CLI_OUT}/lb.png"
            -DEXIT=2 "-DPATTERN=--lod-budget" -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
endforeach()
add_test(NAME cli.good_scene_renders
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;-q;${BAD}/good.json;-o;${CLI_OUT}/good.png"
          -DEXIT=0 -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)

# Same bytes for 1 and 2 threads, through the real command line (PNG and PFM).
set(P4 ${PROJECT_SOURCE_DIR}/examples/plate4-fuzzy-sphere-1000.json)
# Each run must really use the threads it was given (the summary says how many), or the
# comparison would compare a render with itself.
foreach(n 1 2)
  add_test(NAME cli.threads_${n}
    COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;${P4};-o;${CLI_OUT}/threads${n}.png;--threads;${n}"
            -DEXIT=0 "-DPATTERN=on ${n} threads" -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
  set_tests_properties(cli.threads_${n} PROPERTIES FIXTURES_SETUP threads_${n})
endforeach()
add_test(NAME cli.threads_identical
  COMMAND ${CMAKE_COMMAND} -E compare_files ${CLI_OUT}/threads1.png ${CLI_OUT}/threads2.png)
set_tests_properties(cli.threads_identical PROPERTIES FIXTURES_REQUIRED "threads_1;threads_2")

# Lattice tables: bad cache directories, corrupt, truncated and mismatched tables, sizes that
# cannot fit, and the cache itself.
foreach(case corrupt truncated other_primitive missing_dir not_a_dir too_big unknown_primitive
             candidates_any_parts sigma_inv_range unknown_encoding point_limit outside_box tilted_tori_fit
             render_then_reuse filter filter_errors)
  add_test(NAME cli.lattice_${case}
    COMMAND ${CMAKE_COMMAND} -DLATTICE=$<TARGET_FILE:lattice> -DEXAMPLES=${PROJECT_SOURCE_DIR}/examples -DDATA=${CMAKE_CURRENT_SOURCE_DIR}/data
            -DWORK=${CLI_OUT}/lattice-${case} -DCASE=${case}
            -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/lattice_cases.cmake)
endforeach()

# Every default path of render (exact, exact with footprint filtering, lattice, auto) against an
# exact many-sample truth, with floors a broken path fails.
add_test(NAME cli.mode_paths
  COMMAND ${CMAKE_COMMAND} -DLATTICE=$<TARGET_FILE:lattice>
          -DSCENE=${CMAKE_CURRENT_SOURCE_DIR}/data/modes/fuzzy-ball.json -DWORK=${CLI_OUT}/mode-paths
          -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/mode_paths.cmake)

# The complexity benchmark's generated scenes load and render (tiny; no ../shared needed).
find_package(Python3 COMPONENTS Interpreter QUIET)
if(Python3_Interpreter_FOUND)
  add_test(NAME cli.complexity_scenes
    COMMAND ${CMAKE_COMMAND} -DLATTICE=$<TARGET_FILE:lattice> -DPYTHON=${Python3_EXECUTABLE}
            -DGEN=${PROJECT_SOURCE_DIR}/bench/complexity_scenes.py -DWORK=${CLI_OUT}/complexity
            -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/complexity_scenes.cmake)
endif()

# Meshes and scatters: bad files and bad parameters, one located line, exit 2.
lattice_cli_error(mesh_missing ${BAD}/mesh-missing.json "mesh-missing.json: objects\\[1\\]\\.file: .*no-such-mesh.obj: cannot open mesh file: No such file or directory")
lattice_cli_error(mesh_no_triangles ${BAD}/mesh-no-triangles.json "objects\\[1\\]\\.file: .*no-triangles.obj: the mesh has no triangles")
lattice_cli_error(mesh_huge_claim ${BAD}/mesh-huge-claim.json "objects\\[1\\]\\.file: .*huge-claim.ply: the file ends after 0 of 9999999 vertices")
lattice_cli_error(mesh_nan_obj ${BAD}/mesh-nan-obj.json "objects\\[1\\]\\.file: .*nan-vertex.obj: line 3: 'nan' is not a finite number")
lattice_cli_error(mesh_nan_ply ${BAD}/mesh-nan-ply.json "objects\\[1\\]\\.file: .*nan-vertex.ply: line 11: 'nan' is not a finite number")
lattice_cli_error(mesh_bad_index ${BAD}/mesh-bad-index.json "objects\\[1\\]\\.file: .*bad-index.obj: line 4: face 1 refers to vertex 9, but 3 vertices come before it")
lattice_cli_error(mesh_random_bytes ${BAD}/mesh-random-bytes.json "objects\\[1\\]\\.file: .*random-bytes.ply: line 1: the PLY header holds the byte .x1f, which is not text")
lattice_cli_error(mesh_open_in_csg ${BAD}/mesh-open-in-csg.json "objects\\[0\\]\\.children\\[1\\]\\.file: an open mesh cannot be a csg leaf")
lattice_cli_error(scatter_huge_count ${BAD}/scatter-huge-count.json "objects\\[0\\]\\.count: 1000000000 instances is over the limit of 50000000")
lattice_cli_error(scatter_no_box ${BAD}/scatter-no-box.json "objects\\[0\\]: missing field 'box': a cone is unbounded")
lattice_cli_error(scatter_bad_scale ${BAD}/scatter-bad-scale.json "objects\\[0\\]\\.scale: min is over max")
foreach(mode exact lattice)
  add_test(NAME cli.scatter_mesh_renders_${mode}
    COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;-q;--mode;${mode};--lattice-dir;${CLI_OUT};${BAD}/scatter-mesh-good.json;-o;${CLI_OUT}/scatter-${mode}.png"
            -DEXIT=0 -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
endforeach()
add_test(NAME cli.scatter_command_unknown_name
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;scatter;${BAD}/scatter-mesh-good.json;--object;fur;-o;${CLI_OUT}/placed.json"
          -DEXIT=2 "-DPATTERN=scatter-mesh-good.json: objects: no scatter is named 'fur'"
          -DNO_FILE=${CLI_OUT}/placed.json -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)

# Table 2: the texture and particle modes' own errors, their options, and table2.
add_test(NAME cli.texture_base_unmappable
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;--mode;texture;${BAD}/texture-halfspace-base.json;-o;${CLI_OUT}/tex.png"
          -DEXIT=2 "-DPATTERN=texture-halfspace-base.json: objects\\[0\\]: the instances grow from this object, and texture mode maps onto spheres, ellipsoids and triangle meshes only"
          -DNO_FILE=${CLI_OUT}/tex.png -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
add_test(NAME cli.particles_need_a_chain
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;--mode;particles;${BAD}/particles-not-chain.json;-o;${CLI_OUT}/par.png"
          -DEXIT=2 "-DPATTERN=particles-not-chain.json: objects\\[1\\]: particle mode needs a sphere/cylinder chain primitive; 'ring'"
          -DNO_FILE=${CLI_OUT}/par.png -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
foreach(mode texture particles)
  add_test(NAME cli.${mode}_mode_renders
    COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;-q;--mode;${mode};--spp;4;${BAD}/furred-sphere.json;-o;${CLI_OUT}/${mode}.png"
            -DEXIT=0 -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
endforeach()
add_test(NAME cli.texture_size_range
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;--mode;texture;--texture-size;1;${BAD}/good.json;-o;${CLI_OUT}/ts.png"
          -DEXIT=2 "-DPATTERN=--texture-size" -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
add_test(NAME cli.shadow_map_size_range
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;--mode;particles;--shadow-map-size;8;${BAD}/good.json;-o;${CLI_OUT}/sm.png"
          -DEXIT=2 "-DPATTERN=--shadow-map-size" -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
add_test(NAME cli.instance_shadows_unknown
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;--mode;lattice;--instance-shadows;map;${BAD}/good.json;-o;${CLI_OUT}/is.png"
          -DEXIT=2 "-DPATTERN=--instance-shadows" -DNO_FILE=${CLI_OUT}/is.png -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
# Deep maps say so on the summary line; asked for where they cannot act, a note says why.
file(MAKE_DIRECTORY ${CLI_OUT}/is-cache)
add_test(NAME cli.instance_shadows_deep_map_says_so
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;--mode;lattice;--lod;off;--instance-shadows;deep-map;--lattice-dir;${CLI_OUT}/is-cache;${BAD}/furred-sphere.json;-o;${CLI_OUT}/isd.png"
          -DEXIT=0 "-DPATTERN=instances' shadows from deep shadow maps of 1 of 1 lights" -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
add_test(NAME cli.instance_shadows_no_effect_in_exact_mode
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;render;--instance-shadows;deep-map;${BAD}/good.json;-o;${CLI_OUT}/ise.png"
          -DEXIT=0 "-DPATTERN=--instance-shadows has no effect in exact mode" -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
add_test(NAME cli.table2_unknown_encoding
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;table2;${BAD}/good.json;-o;${CLI_OUT}/t2bad;--encodings;hash14,nope"
          -DEXIT=2 "-DPATTERN=nope" -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
file(MAKE_DIRECTORY ${CLI_OUT}/t2-cache ${CLI_OUT}/t2tex-cache)
# A base the texture mode cannot map leaves its row out, said why; the other modes are measured.
add_test(NAME cli.table2_unmappable_base_leaves_texture_out
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;table2;${BAD}/texture-halfspace-base.json;-o;${CLI_OUT}/t2tex;--truth-spp;1;--spp;1;--encodings;hash14;--filter;none;--lattice-dir;${CLI_OUT}/t2tex-cache"
          -DEXIT=0 "-DPATTERN=table2: texture: not measured: .*objects\\[0\\]: the instances grow from this object"
          "-DSTDOUT_PATTERN=\\| lattice-hash14 \\|.*Texture mapping not measured: .*objects\\[0\\]"
          -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
add_test(NAME cli.table2_runs
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;table2;${BAD}/furred-sphere.json;-o;${CLI_OUT}/t2;--truth-spp;4;--spp;2;--encodings;hash14,dense;--lattice-dir;${CLI_OUT}/t2-cache;--texture-size;64"
          -DEXIT=0 "-DPATTERN=table2: lattice-dense" "-DSTDOUT_PATTERN=\\| lattice-coverage-smooth \\| 1 \\|.*Crops \\(`crops.png`\\)"
          -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
# compare prints SSIM, here of two of table2's images.
add_test(NAME cli.compare_prints_ssim
  COMMAND ${CMAKE_COMMAND} "-DCMD=$<TARGET_FILE:lattice>;compare;${CLI_OUT}/t2/truth.png;${CLI_OUT}/t2/texture.png"
          -DEXIT=0 "-DSTDOUT_PATTERN=ssim: 0\\.[0-9][0-9][0-9][0-9]" -DWORKDIR=${CLI_OUT} -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect.cmake)
set_tests_properties(cli.compare_prints_ssim PROPERTIES DEPENDS cli.table2_runs)

# Under mpirun, when the build found MPI: 2 ranks against 1 process, and errors.
# Not in the sanitizer build: Open MPI is not instrumented, and LSan would report its
# allocations that outlive MPI_Finalize.
if(LATTICE_WITH_MPI AND MPIEXEC_EXECUTABLE AND NOT LATTICE_SANITIZE)
  foreach(case render_exact render_lattice rasterize rank0_modes errors)
    add_test(NAME cli.mpi_${case}
      COMMAND ${CMAKE_COMMAND} -DLATTICE=$<TARGET_FILE:lattice> -DMPIEXEC=${MPIEXEC_EXECUTABLE}
              -DEXAMPLES=${PROJECT_SOURCE_DIR}/examples -DDATA=${CMAKE_CURRENT_SOURCE_DIR}/data
              -DWORK=${CLI_OUT}/mpi-${case} -DCASE=${case}
              -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/mpi_cases.cmake)
    # Open MPI refuses to run as root unless told (CI runs as root); two ranks on two cores.
    set_tests_properties(cli.mpi_${case} PROPERTIES
      ENVIRONMENT "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1" PROCESSORS 2 TIMEOUT 300)
  endforeach()
endif()
