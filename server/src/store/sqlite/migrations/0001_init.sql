-- 0001: jobs with their spec and life cycle; result files of finished jobs.
-- Released: never edit, add a new migration instead.
CREATE TABLE jobs (
  seq INTEGER PRIMARY KEY AUTOINCREMENT,
  id TEXT NOT NULL UNIQUE,
  name TEXT NOT NULL,
  spec TEXT NOT NULL,
  status TEXT NOT NULL CHECK (status IN ('accepted','running','successful','failed','dismissed')),
  progress REAL NOT NULL DEFAULT 0,
  message TEXT NOT NULL DEFAULT '',
  created TEXT NOT NULL,
  started TEXT,
  finished TEXT,
  updated TEXT NOT NULL,
  attempts INTEGER NOT NULL DEFAULT 0,
  failure_reason TEXT,
  idempotency_key TEXT UNIQUE,
  body_sha256 TEXT,
  cost_particles INTEGER NOT NULL DEFAULT 0,
  cost_nodes INTEGER NOT NULL DEFAULT 0,
  cost_cells INTEGER NOT NULL DEFAULT 0,
  cost_steps INTEGER NOT NULL DEFAULT 0,
  cost_particle_steps INTEGER NOT NULL DEFAULT 0,
  cost_memory_bytes INTEGER NOT NULL DEFAULT 0,
  cost_output_bytes INTEGER NOT NULL DEFAULT 0,
  cost_dt REAL NOT NULL DEFAULT 0,
  run_seconds REAL NOT NULL DEFAULT 0
);
CREATE INDEX jobs_by_status ON jobs (status, seq);
CREATE TABLE results (
  job_id TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  name TEXT NOT NULL,
  size INTEGER NOT NULL,
  sha256 TEXT NOT NULL,
  media_type TEXT NOT NULL,
  PRIMARY KEY (job_id, name)
);
