# Installs the Node.js test's packages into the build folder with `npm ci` (exact versions from
# package-lock.json), once: a stamp holding the lock file's hash skips it while nothing changed.
# Arguments: NPM, WORKDIR (holding package.json and package-lock.json).
file(SHA256 ${WORKDIR}/package-lock.json lock_hash)
set(stamp ${WORKDIR}/node_modules/.lidarloop-installed)
if(EXISTS ${stamp})
  file(READ ${stamp} installed)
  if(installed STREQUAL lock_hash)
    message(STATUS "node packages up to date in ${WORKDIR}/node_modules")
    return()
  endif()
endif()
execute_process(COMMAND ${NPM} ci --no-audit --no-fund --ignore-scripts WORKING_DIRECTORY ${WORKDIR}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "npm ci failed (${code}) in ${WORKDIR}:\n${out}\n${err}")
endif()
file(WRITE ${stamp} "${lock_hash}")
