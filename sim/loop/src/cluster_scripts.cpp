// Slurm job scripts for one `ofv compare` sweep.
#include "ofv/loop/cluster_scripts.h"

#include "ofv/version.h"

#include <filesystem>
#include <stdexcept>

namespace ofv {

std::string shell_quote(const std::string& text) {
  std::string out = "'";
  for (const char ch : text) out += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return out + "'";
}

std::vector<std::pair<std::string, std::string>> slurm_job_scripts(const SlurmSweep& s) {
  if (s.parts < 1 || s.parts > kMaxSlurmParts) {
    throw std::invalid_argument("--slurm-script: expected a number of array tasks in 1.." +
                                std::to_string(kMaxSlurmParts) + ", got " + std::to_string(s.parts));
  }
  if (s.cpus < 1 || s.cpus > 256) {
    throw std::invalid_argument("--slurm-script: CPUs per task must be in 1..256, got " + std::to_string(s.cpus));
  }
  std::vector<std::string> paths{s.ofv, s.grid, s.out};
  paths.insert(paths.end(), s.scenarios.begin(), s.scenarios.end());
  for (const auto& p : paths) {
    if (!std::filesystem::path(p).is_absolute()) throw std::invalid_argument("--slurm-script: not an absolute path: " + p);
  }
  const std::string n = std::to_string(s.parts);
  const std::string out = shell_quote(s.out);
  const std::string header = std::string("# Written by ofv ") + version() + " (git " + git_commit() +
                             ") for one `ofv compare` sweep (docs/compare.md).\n"
                             "# Add the #SBATCH lines your cluster needs (--partition, --time, --account).\n";
  std::string scenarios;
  for (const auto& p : s.scenarios) scenarios += " " + shell_quote(p);

  std::string sweep = "#!/bin/bash\n" + header +
                      "# Task K of the array runs part K/" + n + " of the sweep into parts/K.\n"
                      "#SBATCH --job-name=ofv-sweep\n"
                      "#SBATCH --array=1-" + n + "\n"
                      "#SBATCH --cpus-per-task=" + std::to_string(s.cpus) + "\n"
                      "set -euo pipefail\n"
                      "exec " + shell_quote(s.ofv) + " compare --scenarios" + scenarios +
                      " \\\n    --grid " + shell_quote(s.grid) + " --seeds " + std::to_string(s.seeds) +
                      " \\\n    --jobs \"${SLURM_CPUS_PER_TASK:-1}\" --shard \"${SLURM_ARRAY_TASK_ID}/" + n +
                      "\" \\\n    --out " + out + "/parts/\"${SLURM_ARRAY_TASK_ID}\"\n";
  std::string parts;
  for (int k = 1; k <= s.parts; ++k) parts += " \\\n    " + out + "/parts/" + std::to_string(k);
  std::string merge = "#!/bin/bash\n" + header +
                      "# Merges the parts into the tables and plots of the whole sweep (submit.sh\n"
                      "# submits it to start once every task of the array has succeeded).\n"
                      "#SBATCH --job-name=ofv-merge\n"
                      "#SBATCH --cpus-per-task=1\n"
                      "set -euo pipefail\n"
                      "exec " + shell_quote(s.ofv) + " compare --merge" + parts + " \\\n    --out " + out + "\n";
  std::string submit = "#!/bin/sh\n" + header +
                       "# Submits the job array, then the merge to run once it has succeeded, their\n"
                       "# logs beside this file; the arguments go to the merge's sbatch (--wait:\n"
                       "# return when it has ended, with its exit status).\n"
                       "set -eu\n"
                       "cd " + out + "/slurm\n"
                       "array=$(sbatch --parsable --output=part-%a.log sweep.sbatch)\n"
                       "echo \"ofv sweep: job array ${array%%;*} (" + n + " tasks)\"\n"
                       "sbatch --parsable --output=merge.log --dependency=afterok:\"${array%%;*}\" \"$@\" merge.sbatch\n";
  return {{"sweep.sbatch", sweep}, {"merge.sbatch", merge}, {"submit.sh", submit}};
}

}  // namespace ofv
