#include "tools/cluster_render.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>

#include "common/input_error.hpp"
#include "scoring/result_files.hpp"
#include "sim/world_assets.hpp"

namespace lidarloop {
namespace {

constexpr size_t kMaxJobName = 50;  // Kubernetes names are DNS labels (63), less the pods' suffixes

std::string read_template(const std::string& path) {
  const std::optional<std::string> text = read_text_file(path);
  if (!text) throw InputError(path + ": cannot read the template");
  return *text;
}

std::string fill(const std::string& path, std::string text, const std::map<std::string, std::string>& values) {
  for (const auto& [key, value] : values) {
    const std::string mark = "{{" + key + "}}";
    for (size_t at = text.find(mark); at != std::string::npos; at = text.find(mark, at + value.size()))
      text.replace(at, mark.size(), value);
  }
  if (const size_t left = text.find("{{"); left != std::string::npos)
    throw InputError(path + ": placeholder " + text.substr(left, text.find("}}", left) + 2 - left) + " has no value");
  return text;
}

// A DNS-1123 label from the sweep's name: bus_occlusion -> bus-occlusion.
std::string job_name(const std::string& name) {
  std::string out;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) ? char(std::tolower(c)) : '-';
  if (out.size() > kMaxJobName) out.resize(kMaxJobName);
  while (!out.empty() && out.back() == '-') out.pop_back();
  if (out.empty() || !std::isalpha(static_cast<unsigned char>(out[0])))
    throw InputError("sweep name '" + name + "' cannot be made a Kubernetes Job name");
  return out;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> render_cluster_job(const ClusterJob& job) {
  std::vector<std::string> files;
  if (job.engine == "kubernetes")
    files = {"sweep-job.yaml", "merge-job.yaml"};
  else if (job.engine == "slurm")
    files = {"sweep-array.sbatch", "submit.sh"};
  else
    throw InputError("--engine must be kubernetes or slurm, got '" + job.engine + "'");
  const std::string name = job_name(job.name);
  const std::map<std::string, std::string> values = {
      {"NAME", name},
      {"SWEEP", job.sweep_file},
      {"SHARDS", std::to_string(job.shards)},
      {"LAST_SHARD", std::to_string(job.shards - 1)},
      {"JOBS", std::to_string(job.jobs_per_shard)},
      {"IMAGE", job.image},
      {"LIDARLOOP", job.lidarloop},
      {"RESULTS", job.results},
  };
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& f : files) {
    const std::string path = data_dir() + "/tools/cluster/" + job.engine + "/" + f;
    out.emplace_back(name + "-" + f, fill(path, read_template(path), values));
  }
  return out;
}

}  // namespace lidarloop
