-- 0004: what a job's run reached, as its worker reports it with the
-- progress (as the SQLite store's 0007): the solver's simulated time and end
-- time, the steps taken and the range of the time step (zeros until it runs).
ALTER TABLE jobs ADD COLUMN run_time DOUBLE PRECISION NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN run_end_time DOUBLE PRECISION NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN run_steps BIGINT NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN run_dt_min DOUBLE PRECISION NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN run_dt_max DOUBLE PRECISION NOT NULL DEFAULT 0;
