# forbid_includes(ROOM DIR...): fails the configuration when a source file of this folder includes
# from one of the folders DIR. Linking would not catch a header-only include, and the dependency
# direction between the rooms (README, "Layout") is what lets the localizer and the log reader run
# without the simulator.
function(forbid_includes)
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp ${CMAKE_CURRENT_SOURCE_DIR}/*.hpp)
  foreach(dir ${ARGN})
    foreach(source ${sources})
      file(STRINGS ${source} found REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]${dir}/")
      if(found)
        message(FATAL_ERROR "${source} includes from ${dir}/, which this folder must not depend on")
      endif()
    endforeach()
  endforeach()
endfunction()
