-- 0005: one row that GET /health rewrites (at most once a second, with
-- short lock and statement limits) to prove the database can still be
-- written; and the identity of the data folder the servers on this database
-- share (the random id in its .hmpm-data-dir file, and the path where the
-- first server found it): a server given another folder refuses to start.
CREATE TABLE store_probe (
  id INTEGER PRIMARY KEY CHECK (id = 1),
  written TEXT NOT NULL
);
CREATE TABLE data_folder (
  id INTEGER PRIMARY KEY CHECK (id = 1),
  identity TEXT NOT NULL,
  path TEXT NOT NULL,
  recorded TEXT NOT NULL
);
