-- 0003: a crash is charged to a running job only when its attempt had been
-- running long enough to be the suspect (as the SQLite store's 0005):
-- `claimed_ms` (claim time) and `alive_ms` (last proof of life: claim, lease
-- renewal, progress) say how long; `charged` counts the crashes charged.
-- Jobs from before keep every attempt charged, as the limit counted them.
ALTER TABLE jobs ADD COLUMN charged INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN claimed_ms BIGINT NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN alive_ms BIGINT NOT NULL DEFAULT 0;
UPDATE jobs SET charged = attempts WHERE status IN ('accepted', 'running');
