# Included at the end of every interface package here: compile the generated sources of each
# target in batches (CMake's unity build). Each generated file is small and parses the same heavy
# headers (rosidl, Fast CDR, Python), so on 2 cores batches of 16 cut the build of acti_msgs from
# ~2.9 to ~1.4 min. The type-description files each define the same static names (the hashes of
# the types they include), so they stay single. Which files are batched changes no type: the
# same code is compiled, only fewer times over the headers. The C++ type supports
# (ACTI_MSGS_CPP=ON) stay single too: batched, one file's template specialisations come after
# another's use of them.
function(acti_unity_build)
  get_property(_targets DIRECTORY PROPERTY BUILDSYSTEM_TARGETS)
  foreach(_target ${_targets})
    get_target_property(_type ${_target} TYPE)
    if(NOT _type MATCHES "LIBRARY$" OR _target MATCHES "_cpp$")
      continue()
    endif()
    set_target_properties(${_target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 16)
    get_target_property(_sources ${_target} SOURCES)
    foreach(_source ${_sources})
      if(_source MATCHES "__description\\.c$")
        set_source_files_properties(${_source} TARGET_DIRECTORY ${_target}
          PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
      endif()
    endforeach()
  endforeach()
endfunction()
acti_unity_build()
