-- 0001: jobs with their spec, life cycle and claim (owner, lease, fencing
-- token); result files of finished jobs; one row per attempt (which server
-- ran which claim, from when to when) for operators and the soak test.
-- Timestamps are RFC 3339 UTC text from the store's clock, as in the SQLite
-- store: fixed-width, so they sort as text. Released: never edit, add a new
-- migration instead.
CREATE TABLE jobs (
  seq BIGSERIAL PRIMARY KEY,
  id TEXT NOT NULL UNIQUE,
  name TEXT NOT NULL,
  spec TEXT NOT NULL,
  status TEXT NOT NULL CHECK (status IN ('accepted','running','successful','failed','dismissed')),
  progress DOUBLE PRECISION NOT NULL DEFAULT 0,
  message TEXT NOT NULL DEFAULT '',
  created TEXT NOT NULL,
  started TEXT,
  finished TEXT,
  updated TEXT NOT NULL,
  attempts INTEGER NOT NULL DEFAULT 0,
  failure_reason TEXT,
  idempotency_key TEXT UNIQUE,
  body_sha256 TEXT,
  cost_particles BIGINT NOT NULL DEFAULT 0,
  cost_nodes BIGINT NOT NULL DEFAULT 0,
  cost_cells BIGINT NOT NULL DEFAULT 0,
  cost_steps BIGINT NOT NULL DEFAULT 0,
  cost_particle_steps BIGINT NOT NULL DEFAULT 0,
  cost_memory_bytes BIGINT NOT NULL DEFAULT 0,
  cost_output_bytes BIGINT NOT NULL DEFAULT 0,
  cost_dt DOUBLE PRECISION NOT NULL DEFAULT 0,
  run_seconds DOUBLE PRECISION NOT NULL DEFAULT 0,
  owner TEXT,
  lease_token BIGINT NOT NULL DEFAULT 0,
  lease_expires_ms BIGINT NOT NULL DEFAULT 0,
  results_deleted BOOLEAN NOT NULL DEFAULT false
);
CREATE INDEX jobs_by_status ON jobs (status, seq);
CREATE INDEX jobs_by_name ON jobs (name, seq);
CREATE INDEX jobs_by_owner ON jobs (owner) WHERE status = 'running';
CREATE TABLE results (
  job_id TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  name TEXT NOT NULL,
  size BIGINT NOT NULL,
  sha256 TEXT NOT NULL,
  media_type TEXT NOT NULL,
  PRIMARY KEY (job_id, name)
);
-- outcome: NULL while the attempt runs (or its server died), then
-- successful / failed / dismissed / requeued / lapsed (taken back by recovery).
CREATE TABLE job_attempts (
  job_id TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  token BIGINT NOT NULL,
  owner TEXT NOT NULL,
  claimed TEXT NOT NULL,
  ended TEXT,
  outcome TEXT,
  PRIMARY KEY (job_id, token)
);
