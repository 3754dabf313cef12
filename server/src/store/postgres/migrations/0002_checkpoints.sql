-- 0002: the last checkpoint a running job recorded (record_checkpoint):
-- its file under the job's folder, the step and simulated time it holds,
-- size and SHA-256, when it was written. Cleared when the job ends; kept by
-- requeue and recovery so that a takeover resumes from it.
ALTER TABLE jobs ADD COLUMN checkpoint_file TEXT;
ALTER TABLE jobs ADD COLUMN checkpoint_step BIGINT NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN checkpoint_time DOUBLE PRECISION NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN checkpoint_size BIGINT NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN checkpoint_sha256 TEXT;
ALTER TABLE jobs ADD COLUMN checkpoint_written TEXT;
