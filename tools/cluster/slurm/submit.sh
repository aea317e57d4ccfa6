#!/bin/bash
# Queues the {{NAME}} sweep's {{SHARDS}}-task array, then its merge once every task has ended (afterany: a
# report even when a task failed; it lists what is missing). Run from the folder holding the scripts.
set -euo pipefail
cd "$(dirname "$0")"
mkdir -p {{RESULTS}}
array=$(sbatch --parsable {{NAME}}-sweep-array.sbatch)
merge=$(sbatch --parsable --dependency=afterany:"${array%%;*}" --job-name={{NAME}}-merge \
  --output={{RESULTS}}/slurm-merge-%j.out --wrap "{{LIDARLOOP}} sweep merge {{RESULTS}}")
echo "sweep array ${array}, merge ${merge}: the report will be in {{RESULTS}} (sweep.csv, sweep.md, plots/)"
