-- 0002: a running job is claimed by one server instance: the owner, a lease
-- that lapses unless the owner's heartbeat renews it, and a fencing token
-- raised by every claim so that writes of an older claim are refused.
ALTER TABLE jobs ADD COLUMN owner TEXT;
ALTER TABLE jobs ADD COLUMN lease_token INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN lease_expires_ms INTEGER NOT NULL DEFAULT 0;
