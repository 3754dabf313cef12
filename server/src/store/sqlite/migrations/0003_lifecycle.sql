-- 0003: cancel keeps a job's files, delete removes them: a dismissed job
-- remembers which. Jobs dismissed before this migration were deleted.
ALTER TABLE jobs ADD COLUMN results_deleted INTEGER NOT NULL DEFAULT 0;
UPDATE jobs SET results_deleted = 1 WHERE status = 'dismissed';
CREATE INDEX jobs_by_name ON jobs (name, seq);
