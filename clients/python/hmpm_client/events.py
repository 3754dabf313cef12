"""A minimal Server-Sent Events reader (the WHATWG `text/event-stream` format).

`read_events(lines)` turns an iterable of raw lines (bytes, as read from an
HTTP response) into `Event(name, data, id)` values: `data:` lines are joined
with newlines, an empty line dispatches the event, lines starting with `:`
(comments, which servers use as heartbeats) are skipped, and an event without
an `event:` field is named `message`. Heartbeats are reported as
`Event("heartbeat", "")` so a caller can notice the stream is alive.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Iterator, Optional


@dataclass
class Event:
    name: str
    data: str
    id: Optional[str] = None


def read_events(lines: Iterable[bytes]) -> Iterator[Event]:
    name = ""
    data: list = []
    event_id: Optional[str] = None
    for raw in lines:
        line = raw.decode("utf-8", errors="replace").rstrip("\r\n")
        if line == "":
            if data or name:
                yield Event(name or "message", "\n".join(data), event_id)
            name, data = "", []
            continue
        if line.startswith(":"):
            yield Event("heartbeat", "")
            continue
        field, sep, value = line.partition(":")
        if sep and value.startswith(" "):
            value = value[1:]
        if field == "event":
            name = value
        elif field == "data":
            data.append(value)
        elif field == "id":
            event_id = value
        # `retry:` and unknown fields are ignored, as the format requires.
    if data:
        yield Event(name or "message", "\n".join(data), event_id)
