# One fuzz test: fuzzes for SECONDS from the seeds, into a corpus kept between runs, and fails on any
# finding (libFuzzer exits non-zero on a crash, a timeout, a leak, running out of memory, or a
# sanitizer report), naming the input it left in FINDINGS. Prints the executions per second.
# -DFUZZER=... -DSECONDS=... -DCORPUS=... -DFINDINGS=... -DSEED_DIRS=a,b -DSEED_FILES=c,d
file(MAKE_DIRECTORY ${CORPUS} ${FINDINGS})
string(REPLACE "," ";" seed_dirs "${SEED_DIRS}")
set(seed_files_option)
if(SEED_FILES)
  set(seed_files_option -seed_inputs=${SEED_FILES})
endif()
get_filename_component(name ${FUZZER} NAME)
# -timeout: an input that takes longer is a hang; -rss_limit_mb: one that needs more memory is a leak or
# an allocation sized by a corrupt length field.
execute_process(COMMAND ${FUZZER} -max_total_time=${SECONDS} -timeout=10 -rss_limit_mb=2048 -print_final_stats=1
                        -artifact_prefix=${FINDINGS}/${name}- ${seed_files_option} ${CORPUS} ${seed_dirs}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REGEX MATCH "stat::number_of_executed_units: *([0-9]+)" runs "${err}")
set(runs ${CMAKE_MATCH_1})
string(REGEX MATCH "stat::average_exec_per_sec: *([0-9]+)" rate "${err}")
set(rate ${CMAKE_MATCH_1})
string(REGEX MATCHALL "cov: [0-9]+ ft: [0-9]+ corp: [0-9]+" progress "${err}")
list(POP_BACK progress last)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "${name}: a finding (exit ${code}); the input is in ${FINDINGS}\n${err}")
endif()
message(STATUS "${name}: ${runs} inputs in ${SECONDS} s, ${rate} per second; at the end ${last}")
