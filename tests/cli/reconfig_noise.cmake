# Self-reconfiguration under sensor noise: worlds/snake_walker_snake.lua (snake, walker, 0.5 m,
# snake) with noise on the docks' proximity, the heading and the position sensors, over 20 seeds
# (rm3d sweep, 2 at a time). At least 18 of the 20 runs must pass every check of the world.
# Run as: cmake -DRM3D=<rm3d> -DSRC=<source dir> -DOUT=<folder> -P reconfig_noise.cmake
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
execute_process(COMMAND ${RM3D} sweep ${SRC}/worlds/snake_walker_snake.lua --param noise=sensors --seeds 1-20
                        --jobs 2 --watchdog 300 --out ${OUT}/runs.jsonl
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT EXISTS ${OUT}/runs.jsonl)
  message(FATAL_ERROR "the sweep wrote nothing (exit ${rc}):\n${out}${err}")
endif()
file(STRINGS ${OUT}/runs.jsonl lines)
list(LENGTH lines runs)
set(passed 0)
foreach(line IN LISTS lines)
  string(JSON code GET "${line}" exit_code)
  string(JSON seed GET "${line}" seed)
  if(code EQUAL 0)
    math(EXPR passed "${passed} + 1")
  else()
    message(STATUS "seed ${seed} failed (exit ${code})")
  endif()
endforeach()
message(STATUS "${passed} of ${runs} noisy runs passed")
if(NOT runs EQUAL 20 OR passed LESS 18)
  message(FATAL_ERROR "expected at least 18 of 20 noisy runs to pass, got ${passed} of ${runs}")
endif()
