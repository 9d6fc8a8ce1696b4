# The fuzz targets (tests/fuzz/fuzz_<name>.cpp), their seed corpora (tests/io/data/fuzz/<corpus>/)
# and what each needs beyond intervox::intervox.
set(INTERVOX_FUZZ_TARGETS grid_file grid_payload octomap_bt ply pcd xyz)
set(INTERVOX_FUZZ_CORPUS_grid_file grid)
set(INTERVOX_FUZZ_CORPUS_grid_payload grid_payload)
set(INTERVOX_FUZZ_CORPUS_octomap_bt bt)
set(INTERVOX_FUZZ_CORPUS_ply ply)
set(INTERVOX_FUZZ_CORPUS_pcd pcd)
set(INTERVOX_FUZZ_CORPUS_xyz xyz)

# intervox_fuzz_target_deps(<target> <name>): links what fuzz_<name>.cpp needs beyond intervox.
function(intervox_fuzz_target_deps target name)
endfunction()
