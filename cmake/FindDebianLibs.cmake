# Debian ships OpenCV's CMake config only in the full libopencv-dev; we need three modules,
# so we locate them directly. nanoflann 1.4.3 is header-only (its config reports 1.4.2).
# Clipper 6 (libpolyclipping-dev) has only a pkg-config file.

find_path(OPENCV4_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4 REQUIRED)
foreach(module core imgproc imgcodecs)
  find_library(OPENCV_${module}_LIBRARY opencv_${module} REQUIRED)
  add_library(opencv::${module} UNKNOWN IMPORTED)
  set_target_properties(opencv::${module} PROPERTIES
    IMPORTED_LOCATION "${OPENCV_${module}_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${OPENCV4_INCLUDE_DIR}")
endforeach()

find_path(NANOFLANN_INCLUDE_DIR nanoflann.hpp REQUIRED)
add_library(nanoflann_headers INTERFACE)
target_include_directories(nanoflann_headers SYSTEM INTERFACE "${NANOFLANN_INCLUDE_DIR}")

find_path(CLIPPER_INCLUDE_DIR polyclipping/clipper.hpp REQUIRED)
find_library(CLIPPER_LIBRARY polyclipping REQUIRED)
add_library(clipper UNKNOWN IMPORTED)
set_target_properties(clipper PROPERTIES
  IMPORTED_LOCATION "${CLIPPER_LIBRARY}"
  INTERFACE_INCLUDE_DIRECTORIES "${CLIPPER_INCLUDE_DIR}")
