# Included at the end of every interface package here: the rosidl generators' commands run
# through generator_cache.py (beside this file), which copies the output of a command whose
# inputs it has seen before, in any clone, instead of running the generator again.
# -DACTI_GENERATOR_CACHE=OFF runs them as they are.
option(ACTI_GENERATOR_CACHE "Keep the rosidl generators' output by content across clones" ON)
if(ACTI_GENERATOR_CACHE AND TARGET Python3::Interpreter)
  get_target_property(_acti_python Python3::Interpreter IMPORTED_LOCATION)
  set(_acti_script "${CMAKE_CURRENT_BINARY_DIR}/generator_cache_python/python")
  file(WRITE "${CMAKE_CURRENT_BINARY_DIR}/python.in"
    "#!/bin/sh\nexec \"${_acti_python}\" \"${CMAKE_CURRENT_LIST_DIR}/generator_cache.py\" \"$@\"\n")
  file(COPY "${CMAKE_CURRENT_BINARY_DIR}/python.in" DESTINATION
    "${CMAKE_CURRENT_BINARY_DIR}/generator_cache_python" FILE_PERMISSIONS OWNER_READ
    OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
  file(RENAME "${CMAKE_CURRENT_BINARY_DIR}/generator_cache_python/python.in" "${_acti_script}")
  set_property(TARGET Python3::Interpreter PROPERTY IMPORTED_LOCATION "${_acti_script}")
  message(STATUS "${PROJECT_NAME}: generators through ${_acti_script} (cache by content)")
endif()
