# The sharding contract: the tiny sweep run in one go, and the same sweep run as four shards in separate
# processes and merged, give the same sweep.csv, byte for byte. Twice: as two tasks of the rendered
# Slurm array script (run with the variables Slurm sets, into one folder) and two `--shard` processes
# (each into its own folder, as on separate disks); and as the four pods of the rendered Kubernetes
# Indexed Job (its container's command with each $JOB_COMPLETION_INDEX, into one folder). And a second
# invocation resumes: nothing is run again.
# -DLIDARLOOP=... -DSWEEP=... -DWORKDIR=...
file(REMOVE_RECURSE ${WORKDIR})
file(MAKE_DIRECTORY ${WORKDIR})

function(run_ok)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "${ARGN}\nexited ${code}\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

function(same_csv a b what)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${a} ${b} RESULT_VARIABLE differ)
  if(differ)
    file(READ ${a} ta)
    file(READ ${b} tb)
    message(FATAL_ERROR "${what}: sweep.csv differs from the unsharded sweep's\n${ta}\n---\n${tb}")
  endif()
endfunction()

run_ok(${LIDARLOOP} sweep ${SWEEP} --jobs 2 --out ${WORKDIR}/whole)
file(STRINGS ${WORKDIR}/whole/sweep.csv rows)
list(LENGTH rows count)
if(NOT count EQUAL 9)  # the header, 4 runs x 2 methods
  message(FATAL_ERROR "expected 8 rows in sweep.csv, got ${count}: ${rows}")
endif()
foreach(row ${rows})
  if(row MATCHES "^00" AND NOT row MATCHES ",done,(true|false),[0-9]")
    message(FATAL_ERROR "a run did not finish with metrics: ${row}")
  endif()
endforeach()
run_ok(${LIDARLOOP} sweep ${SWEEP} --jobs 2 --out ${WORKDIR}/whole)
if(NOT last_output MATCHES "4 already complete, 0 to run")
  message(FATAL_ERROR "a second invocation did not resume:\n${last_output}")
endif()

# Slurm: render the array for 4 shards and run its script as Slurm would run each task.
run_ok(${LIDARLOOP} sweep render ${SWEEP} --engine slurm --shards 4 --jobs 1 --lidarloop ${LIDARLOOP}
       --results ${WORKDIR}/slurm --out ${WORKDIR}/rendered_slurm)
file(GLOB sbatch ${WORKDIR}/rendered_slurm/*-sweep-array.sbatch)
file(READ ${sbatch} script)
if(NOT script MATCHES "#SBATCH --array=0-3\n" OR NOT script MATCHES "#SBATCH --cpus-per-task=1\n")
  message(FATAL_ERROR "the Slurm script does not ask for tasks 0-3 of one core each:\n${script}")
endif()
file(GLOB submit ${WORKDIR}/rendered_slurm/*-submit.sh)
file(READ ${submit} submit_script)
if(NOT submit_script MATCHES "--dependency=afterany:" OR NOT submit_script MATCHES "sweep merge ${WORKDIR}/slurm\"")
  message(FATAL_ERROR "the submit script does not queue the merge after the array:\n${submit_script}")
endif()
# The script keeps its map cache beside its results (a cluster's shared disk), where the first task
# would build the campus map again: a minute of survey that the sharding contract does not need. The
# map the test fixture built is linked in instead (map determinism has tests of its own).
execute_process(COMMAND ${LIDARLOOP} map campus RESULT_VARIABLE code OUTPUT_VARIABLE map_out ERROR_VARIABLE map_err)
if(NOT code EQUAL 0 OR NOT map_out MATCHES "map +([^\n]+) \\(found in the cache\\)")
  message(FATAL_ERROR "the campus map is not in the cache:\n${map_out}\n${map_err}")
endif()
set(campus_map ${CMAKE_MATCH_1})
get_filename_component(campus_map_name ${campus_map} NAME)
file(MAKE_DIRECTORY ${WORKDIR}/slurm/map-cache)
file(CREATE_LINK ${campus_map} ${WORKDIR}/slurm/map-cache/${campus_map_name} SYMBOLIC)
# Tasks 0 and 1 as Slurm runs them; shards 2 and 3 by --shard, each into its own folder (as on
# separate disks).
foreach(task 0 1)
  run_ok(${CMAKE_COMMAND} -E env SLURM_ARRAY_TASK_ID=${task} SLURM_ARRAY_TASK_MIN=0 SLURM_ARRAY_TASK_COUNT=4
         bash ${sbatch})
endforeach()
foreach(shard 2 3)
  run_ok(${LIDARLOOP} sweep ${SWEEP} --shard ${shard}/4 --jobs 1 --out ${WORKDIR}/shard_${shard})
endforeach()
execute_process(COMMAND ${LIDARLOOP} sweep merge ${WORKDIR}/slurm ${WORKDIR}/shard_2 RESULT_VARIABLE code
                OUTPUT_VARIABLE out)
if(NOT code EQUAL 1 OR NOT out MATCHES "missing    1 runs")
  message(FATAL_ERROR "merging three of four shards must report the run missing (exit 1), got ${code}:\n${out}")
endif()
run_ok(${LIDARLOOP} sweep merge ${WORKDIR}/slurm ${WORKDIR}/shard_2 ${WORKDIR}/shard_3 --out ${WORKDIR}/merged)
same_csv(${WORKDIR}/whole/sweep.csv ${WORKDIR}/merged/sweep.csv "two Slurm tasks and two --shard processes merged")

# Kubernetes: the Indexed Job's counts and the container's command, run as each pod would run it.
run_ok(${LIDARLOOP} sweep render ${SWEEP} --engine kubernetes --shards 4 --jobs 1 --lidarloop ${LIDARLOOP}
       --results ${WORKDIR}/k8s --image registry.example/lidarloop:1 --out ${WORKDIR}/rendered_k8s)
file(GLOB job ${WORKDIR}/rendered_k8s/*-sweep-job.yaml)
file(READ ${job} manifest)
foreach(line "completionMode: Indexed" "completions: 4" "parallelism: 4" "image: registry.example/lidarloop:1")
  if(NOT manifest MATCHES "${line}")
    message(FATAL_ERROR "the Job lacks '${line}':\n${manifest}")
  endif()
endforeach()
string(REGEX MATCH "args: \\[([^]]*)\\]" args "${manifest}")
string(REGEX REPLACE "\"|,|args: |\\[|\\]" "" args "${CMAKE_MATCH_1}")
separate_arguments(args UNIX_COMMAND "${args}")
if(NOT args MATCHES "sweep;${SWEEP};--shards;4;--jobs;1;--out;${WORKDIR}/k8s")
  message(FATAL_ERROR "unexpected container args: ${args}")
endif()
foreach(index 0 1 2 3)
  run_ok(${CMAKE_COMMAND} -E env JOB_COMPLETION_INDEX=${index} ${LIDARLOOP} ${args})
endforeach()
file(GLOB merge_job ${WORKDIR}/rendered_k8s/*-merge-job.yaml)
file(READ ${merge_job} merge_manifest)
if(NOT merge_manifest MATCHES "args: \\[\"sweep\", \"merge\", \"${WORKDIR}/k8s\"\\]")
  message(FATAL_ERROR "the merge Job does not merge ${WORKDIR}/k8s:\n${merge_manifest}")
endif()
run_ok(${LIDARLOOP} sweep merge ${WORKDIR}/k8s)
same_csv(${WORKDIR}/whole/sweep.csv ${WORKDIR}/k8s/sweep.csv "the Kubernetes Indexed Job")
