/**
 * \file cluster_scripts.h
 * \brief Job scripts that run one `ofv compare` sweep as a Slurm job array
 *        and merge its parts in a job that depends on the array
 *        (`ofv compare --slurm-script N`, docs/compare.md).
 */
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace ofv {

/// \brief The sweep the scripts run, as `ofv compare` was given it.
struct SlurmSweep {
  std::string ofv;                     ///< absolute path of the ofv program the jobs run
  std::vector<std::string> scenarios;  ///< absolute paths of the scenario files
  std::string grid;                    ///< absolute path of the grid file
  int seeds = 1;                       ///< seeds per scenario x variant
  int parts = 1;                       ///< array tasks: part K of N runs in task K
  int cpus = 1;                        ///< CPUs of each task (`--cpus-per-task`, the part's `--jobs`)
  std::string out;                     ///< absolute output folder: parts in out/parts/K, the merge in out
};

/// \brief Most array tasks `--slurm-script` writes for (Slurm's default MaxArraySize is 1001).
inline constexpr int kMaxSlurmParts = 1000;

/**
 * \brief The scripts, as (file name, text), to be written to `out/slurm/`:
 *        `sweep.sbatch` (the job array: task K runs `--shard K/N` into
 *        `out/parts/K` with `--jobs $SLURM_CPUS_PER_TASK`), `merge.sbatch`
 *        (`--merge` of every part into `out`) and `submit.sh`, which submits
 *        the array, then the merge with `--dependency=afterok:` on it, passing
 *        its own arguments to the merge's `sbatch` (`submit.sh --wait`
 *        returns when the merge has ended, with its exit status).
 *        Every path is quoted for the shell.
 * \throws std::invalid_argument unless 1 <= parts <= kMaxSlurmParts,
 *         1 <= cpus <= 256 and every path is absolute.
 */
[[nodiscard]] std::vector<std::pair<std::string, std::string>> slurm_job_scripts(const SlurmSweep& sweep);

/// \brief `text` quoted for a POSIX shell: in single quotes, each `'` written `'\''`.
[[nodiscard]] std::string shell_quote(const std::string& text);

}  // namespace ofv
