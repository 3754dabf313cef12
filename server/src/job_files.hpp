// job_files.hpp — a job's folder on disk, in one place.
//
//   <data-dir>/<job id>/                    the job's folder
//     job.log                               its log, across attempts (run_log.hpp)
//     attempt-<fencing token>/              what one claim writes: the result
//       <result files>                      files (the manifest lists them) and
//       checkpoint-<token>-<step>.hmpmck    its checkpoints
//
// Each claim writes only into its own attempt folder; the files served are
// those of the claim whose token the job row keeps (results_dir). Jobs
// that ended before attempt folders existed keep their files in the job's
// folder itself. The workers (workers/), the HTTP handlers (log, cancel,
// delete, result files) and retention all find the folder here.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "hmpm/server/store.hpp"

namespace hmpm::server {

class JobFiles {
 public:
  explicit JobFiles(std::filesystem::path data_dir) : data_dir_(std::move(data_dir)) {}

  /// The folder that holds every job's.
  const std::filesystem::path& data_dir() const { return data_dir_; }
  /// The folder of job `id`: its log and one folder per attempt.
  std::filesystem::path job_dir(const std::string& id) const { return data_dir_ / id; }
  /// The job's log file.
  std::filesystem::path log_file(const std::string& id) const;
  /// Where the attempt of `claim` writes its result and checkpoint files.
  std::filesystem::path attempt_dir(const Claim& claim) const;
  /// Where the result files of the ended job `job` live: the folder of the
  /// claim that recorded them (its token is the row's), or the job folder
  /// itself for a job that ended before attempt folders existed.
  std::filesystem::path results_dir(const JobRecord& job) const;
  /// Removes the job's folder with everything in it; false if that failed.
  bool remove(const std::string& id) const;

 private:
  std::filesystem::path data_dir_;
};

/// The name of the attempt folder of the claim with fencing token `token`.
std::string attempt_name(std::int64_t token);

/// The checkpoint file of `claim` at `step`, relative to the job's folder:
/// "attempt-<token>/checkpoint-<token>-<step>.hmpmck".
std::string checkpoint_path(const Claim& claim, std::int64_t step);

/// Removes everything in `dir` but the job's log (it spans every attempt)
/// and the entry named `keep` (an attempt folder), if any.
void remove_all_but_log(const std::filesystem::path& dir, const std::string& keep = "");

/// Removes every file of `dir` that is neither the job's log nor one of
/// `listed` (the manifest): nothing stays in a job's folder that its manifest
/// does not show (the leftovers of a failed write hold space and are invisible).
void remove_unlisted(const std::filesystem::path& dir, const std::vector<ResultFile>& listed);

/// Copies the result files an earlier attempt wrote in `from` (the snapshots
/// before its checkpoint) into this attempt's folder `to`: a resumed run
/// writes only what comes after the checkpoint. Copies, not links: a revived
/// earlier owner rewriting its own files must not change ours. Throws
/// std::filesystem::filesystem_error.
void carry_over(const std::filesystem::path& from, const std::filesystem::path& to);

/// Removes the job's checkpoint files in `dir` but `keep` (and any half-written one).
void remove_checkpoints_but(const std::filesystem::path& dir, const std::string& keep = "");

/// Writes `bytes` to `path` durably: a temporary file, fsync, rename over
/// `path`, fsync of the folder. Throws std::runtime_error.
void write_durably(const std::filesystem::path& path, const std::string& bytes);

/// The bytes of the checkpoint file `path`, which must be a regular file
/// of `expected_size` bytes. Opened without blocking (O_NONBLOCK: a FIFO
/// put in its place opens at once) and checked with fstat before a byte is
/// read, so a directory, a FIFO, a device (a symlink to /dev/zero) or a
/// file of another size is refused at once, never read until it ends.
/// Throws std::runtime_error saying which.
std::string read_checkpoint_file(const std::filesystem::path& path, std::int64_t expected_size);

/// Size, SHA-256 and media type of each of `names` in `dir`, appended to
/// `files`; the name of the first one that cannot be read back, if any.
std::optional<std::string> record_files(const std::filesystem::path& dir,
                                        const std::vector<std::string>& names,
                                        std::vector<ResultFile>& files);

}  // namespace hmpm::server
