-- 0007: what a job's run reached, as its worker reports it with the
-- progress: the solver's simulated time and end time, the steps taken and
-- the range of the time step (zeros until it runs; jobs from before keep
-- zeros).
ALTER TABLE jobs ADD COLUMN run_time REAL NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN run_end_time REAL NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN run_steps INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN run_dt_min REAL NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN run_dt_max REAL NOT NULL DEFAULT 0;
