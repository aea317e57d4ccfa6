# Checks that a localizer's covariance is honest: its mean NEES (metrics.json consistency.mean_nees_*,
# e^2 / sigma^2 per axis: 1 when the covariance matches the errors) within [NEES_MIN, NEES_MAX], the
# band issue 40 sets for the shipped examples. Included by the external example tests.
#
# One 20 s run of a GPS-grade filter is nearly one draw of the receiver's bias (it wanders over
# minutes), so one axis's NEES of one run is about a chi-square of one degree of freedom: an honest
# filter lands outside [0.5, 2] on most seeds. Hence two checks: on one run, the mean of the lateral and
# longitudinal NEES (the position's, two degrees of freedom) and the heading's; over several seeds
# (nees_over_seeds), each axis's mean over the runs.
set(NEES_MIN 0.5)
set(NEES_MAX 2.0)
# CMake's math() is integer only: NEES values are compared and averaged in millionths.
set(NEES_SCALE 1000000)

# to_millionths(OUT VALUE): a JSON number (no exponent, or a tiny one) as an integer count of millionths.
function(to_millionths out value)
  if(value MATCHES "[eE]-")
    set(${out} 0 PARENT_SCOPE)  # below 1e-4 at most: far under the band either way
    return()
  endif()
  if(NOT value MATCHES "^([0-9]+)(\\.([0-9]*))?$")
    message(FATAL_ERROR "not a plain non-negative number: '${value}'")
  endif()
  set(whole ${CMAKE_MATCH_1})
  string(SUBSTRING "${CMAKE_MATCH_3}000000" 0 6 fraction)
  string(REGEX REPLACE "^0+([0-9])" "\\1" fraction "${fraction}")
  math(EXPR result "${whole} * ${NEES_SCALE} + ${fraction}")
  set(${out} ${result} PARENT_SCOPE)
endfunction()

# nees_millionths(OUT METRICS_JSON_TEXT AXIS): consistency.mean_nees_AXIS in millionths.
function(nees_millionths out json axis)
  string(JSON value ERROR_VARIABLE missing GET "${json}" consistency mean_nees_${axis})
  if(missing OR value STREQUAL "null")
    message(FATAL_ERROR "metrics.json has no consistency.mean_nees_${axis}: the program reported no covariance")
  endif()
  to_millionths(m ${value})
  set(${out} ${m} PARENT_SCOPE)
endfunction()

function(require_in_band what millionths)
  to_millionths(low ${NEES_MIN})
  to_millionths(high ${NEES_MAX})
  math(EXPR whole "${millionths} / ${NEES_SCALE}")
  math(EXPR frac "${millionths} % ${NEES_SCALE}")
  string(LENGTH "${frac}" digits)
  while(digits LESS 6)
    set(frac "0${frac}")
    math(EXPR digits "${digits} + 1")
  endwhile()
  if(millionths LESS low OR millionths GREATER high)
    message(FATAL_ERROR "${what} ${whole}.${frac} is outside [${NEES_MIN}, ${NEES_MAX}]: the covariance is not honest")
  endif()
  message(STATUS "${what} ${whole}.${frac}, within [${NEES_MIN}, ${NEES_MAX}]")
endfunction()

# nees_one_run(METRICS_JSON_FILE): the position's (mean of lateral and longitudinal) and the heading's.
function(nees_one_run file)
  file(READ ${file} json)
  nees_millionths(lateral "${json}" lateral)
  nees_millionths(longitudinal "${json}" longitudinal)
  nees_millionths(heading "${json}" heading)
  math(EXPR position "(${lateral} + ${longitudinal}) / 2")
  require_in_band("mean NEES of the position (lateral and longitudinal)" ${position})
  require_in_band("mean NEES of the heading" ${heading})
endfunction()

# nees_over_seeds(FILE...): each axis's NEES averaged over the runs.
function(nees_over_seeds)
  list(LENGTH ARGN runs)
  if(runs EQUAL 0)
    message(FATAL_ERROR "no metrics.json to check")
  endif()
  foreach(axis lateral longitudinal heading)
    set(sum 0)
    foreach(file ${ARGN})
      file(READ ${file} json)
      nees_millionths(m "${json}" ${axis})
      math(EXPR sum "${sum} + ${m}")
    endforeach()
    math(EXPR mean "${sum} / ${runs}")
    require_in_band("mean NEES ${axis} over ${runs} seeds" ${mean})
  endforeach()
endfunction()
