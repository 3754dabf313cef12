-- 0006: a running job's last checkpoint (the solver state after `step`, in
-- the file named here under the job's data folder). One row per job at
-- most; kept while the job is requeued, deleted when the job ends.
CREATE TABLE checkpoints (
  job_id TEXT PRIMARY KEY,
  file TEXT NOT NULL,
  step INTEGER NOT NULL,
  time REAL NOT NULL,
  size INTEGER NOT NULL,
  sha256 TEXT NOT NULL,
  written TEXT NOT NULL
);
