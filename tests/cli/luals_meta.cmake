# The LuaLS definitions (lua/meta/*.lua) document every name the bindings give scripts: the
# methods of the handle types, from the binding tables (luaL_Reg in engine/script/*.cpp), and the
# functions and globals of both VMs, enumerated at run time by a probe world (tests/cli/luals/).
# A bound name missing from lua/meta fails this test, so the definitions cannot drift.
# Run as: cmake -DRM3D=<rm3d> -DSRC=<source dir> -P luals_meta.cmake
file(GLOB metas ${SRC}/lua/meta/*.lua)
set(meta "")
foreach(m ${metas})
  file(READ ${m} t)
  string(APPEND meta "${t}")
endforeach()
set(missing "")
function(need what)
  foreach(p ${ARGN})
    string(FIND "${meta}" "${p}" at)
    if(NOT at EQUAL -1)
      return()
    endif()
  endforeach()
  set(missing "${missing}\n  ${what}" PARENT_SCOPE)
endfunction()

# Handle methods and library functions, from the binding tables.
foreach(pair "behaviour_joint.cpp:Joint:" "behaviour_dock.cpp:Dock:" "world_body.cpp:Body:" "world_cloth.cpp:Cloth:" "world_heightfield.cpp:Heightfield:"
             "world_module.cpp:Module:" "world_api.cpp:world." "behaviour_sim.cpp:sim."
             "world_particles.cpp:Particles:")
  string(REGEX REPLACE ":.*" "" file "${pair}")
  string(REGEX MATCH "[A-Za-z]+[:.]$" owner "${pair}")
  file(READ ${SRC}/engine/script/${file} text)
  string(REGEX MATCHALL "\\{\"[a-z_]+\", [A-Za-z]+\\}" regs "${text}")
  foreach(r ${regs})
    string(REGEX REPLACE "\\{\"([a-z_]+)\".*" "\\1" name "${r}")
    if(NOT (name STREQUAL "velocity" AND owner STREQUAL "Module:" AND r MATCHES "fields"))
      need("${owner}${name} (${file})" "function ${owner}${name}(")
    endif()
  endforeach()
endforeach()

# Everything the VMs hold at run time.
execute_process(COMMAND ${RM3D} run ${SRC}/tests/cli/luals/probe_world.lua RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(all "${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the probe world failed (exit ${rc}):\n${all}")
endif()
foreach(kind world module sim world_globals behaviour_globals)
  string(REGEX MATCH "LUALS ${kind} [^\n]*" line "${all}")
  if(line STREQUAL "")
    message(FATAL_ERROR "the probe printed no '${kind}' names:\n${all}")
  endif()
  string(REGEX REPLACE "LUALS ${kind} ?" "" line "${line}")
  string(REPLACE " " ";" names "${line}")
  foreach(n ${names})
    if(kind STREQUAL "world" OR kind STREQUAL "module" OR kind STREQUAL "sim")
      need("${kind}.${n}" "function ${kind}.${n}(" "@field ${n} ")
    else()
      need("global ${n} (${kind})" "\n${n} = " "function ${n}(" "\nfunction ${n}(")
    endif()
  endforeach()
endforeach()
if(missing)
  message(FATAL_ERROR "lua/meta/*.lua does not document:${missing}")
endif()
message(STATUS "every bound name is documented in lua/meta")
