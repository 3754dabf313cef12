-- 0004: one row that GET /health rewrites (at most once a second) to prove
-- the database can still be written, not only read.
CREATE TABLE store_probe (
  id INTEGER PRIMARY KEY CHECK (id = 1),
  written TEXT NOT NULL
);
