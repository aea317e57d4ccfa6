#pragma once
// The files that run a sweep on a cluster engine people already operate, from the templates in
// tools/cluster/: a Kubernetes Indexed Job (one pod per shard, $JOB_COMPLETION_INDEX) and a merge Job,
// or a Slurm array script ($SLURM_ARRAY_TASK_ID) and a submit script that queues the merge after it.
#include <string>
#include <utility>
#include <vector>

namespace lidarloop {

struct ClusterJob {
  std::string engine;      // kubernetes | slurm
  std::string name;        // the sweep's name (a Job name: lower case, digits, '-')
  std::string sweep_file;  // as the cluster's nodes see it (the repository's path in the image)
  int shards = 4;
  int jobs_per_shard = 2;  // runs at once in each shard, and the cores it asks for
  std::string image = "lidarloop:latest";
  std::string lidarloop = "lidarloop";  // the executable on the nodes
  std::string results;                  // the shared folder every shard writes into
};

// (file name, contents) of each file, the templates' {{PLACEHOLDERS}} filled. InputError for an
// unknown engine, a name that cannot be a Job's, or a template with a placeholder left unfilled.
std::vector<std::pair<std::string, std::string>> render_cluster_job(const ClusterJob& job);

}  // namespace lidarloop
