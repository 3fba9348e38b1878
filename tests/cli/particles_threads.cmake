# Fluid and debris give the same run with 1 and 2 threads: worlds/fluid.lua (scaled down) and
# worlds/debris.lua run with --threads 1 and 2, and their JSON summaries' particles and modules
# (positions, orientations, joints) must match exactly.
# Run as: cmake -DRM3D=<rm3d> -DSRC=<source dir> -DOUT=<folder> -P particles_threads.cmake
file(MAKE_DIRECTORY ${OUT})
foreach(world "fluid.lua;--param;particles=3000" "debris.lua;--param;spacing=0.02")
  list(GET world 0 file)
  list(SUBLIST world 1 -1 extra)
  set(parts "")
  foreach(threads 1 2)
    set(json ${OUT}/${file}_${threads}.json)
    execute_process(COMMAND ${RM3D} run ${SRC}/worlds/${file} --headless --quiet --seconds 1 --threads ${threads}
                            ${extra} --json ${json} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "${file} with ${threads} threads failed (exit ${rc}):\n${out}${err}")
    endif()
    file(READ ${json} summary)
    string(JSON particles GET "${summary}" particles)
    string(JSON modules GET "${summary}" modules)
    list(APPEND parts "${particles}${modules}")
  endforeach()
  list(GET parts 0 one)
  list(GET parts 1 two)
  if(NOT one STREQUAL two)
    message(FATAL_ERROR "${file}: 1 and 2 threads differ:\n${one}\n---\n${two}")
  endif()
  message(STATUS "${file}: 1 and 2 threads give the same particles and modules")
endforeach()
