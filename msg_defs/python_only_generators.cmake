# Included after find_package(rosidl_default_generators) by every interface package here
# (acti_msgs, and tf2_msgs where it is built): unless ACTI_MSGS_CPP is ON, only the generators a
# Python process needs run (msg_defs/CMakeLists.txt says which and why).
if(NOT ACTI_MSGS_CPP)
  # Every generator found (also through the runtime packages) registered itself as an extension
  # of rosidl_generate_interfaces, in the order they must run: keep Python's, in that order.
  set(_python_generators rosidl_generator_type_description rosidl_generator_c
    rosidl_typesupport_fastrtps_c rosidl_typesupport_introspection_c rosidl_typesupport_c
    rosidl_generator_py)
  set(_kept "")
  foreach(_extension ${AMENT_EXTENSIONS_rosidl_generate_idl_interfaces})
    string(REGEX REPLACE ":.*" "" _generator "${_extension}")
    if(_generator IN_LIST _python_generators)
      list(APPEND _kept "${_extension}")
    endif()
  endforeach()
  set(AMENT_EXTENSIONS_rosidl_generate_idl_interfaces ${_kept})
endif()
message(STATUS "${PROJECT_NAME} generators: ${AMENT_EXTENSIONS_rosidl_generate_idl_interfaces}")
