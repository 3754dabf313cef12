-- 0005: ensembles (contract v3, POST /ensembles), as the SQLite store's
-- 0008: the request as submitted, its seed and what the client did to it
-- (state); the samples are ordinary jobs that name their ensemble and their
-- index in it. Stored with its samples in one transaction. An ensemble goes
-- when retention has purged its last sample.
CREATE TABLE ensembles (
  seq BIGSERIAL PRIMARY KEY,
  id TEXT NOT NULL UNIQUE,
  request TEXT NOT NULL,
  seed BIGINT NOT NULL,
  samples INTEGER NOT NULL,
  state TEXT NOT NULL DEFAULT 'active' CHECK (state IN ('active','cancelled','deleted')),
  created TEXT NOT NULL,
  updated TEXT NOT NULL,
  idempotency_key TEXT UNIQUE,
  body_sha256 TEXT
);
ALTER TABLE jobs ADD COLUMN ensemble_id TEXT;
ALTER TABLE jobs ADD COLUMN ensemble_index INTEGER NOT NULL DEFAULT -1;
CREATE INDEX jobs_by_ensemble ON jobs (ensemble_id, ensemble_index) WHERE ensemble_id IS NOT NULL;
