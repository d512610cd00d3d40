"""A reader of LCM log files (what lcm-logger writes), written for the tests so that the
transport under test is checked against LCM's own C code, not against itself."""

import struct

SYNC = 0xEDA1DA01
_EVENT = struct.Struct(">IqqII")  # sync, event number, utime, channel length, data length


def read_events(path):
    """[(channel, payload bytes)] in the order they were logged."""
    events = []
    with open(path, "rb") as f:
        blob = f.read()
    pos = 0
    while pos + _EVENT.size <= len(blob):
        sync, _, _, channel_len, data_len = _EVENT.unpack_from(blob, pos)
        if sync != SYNC:
            raise ValueError(f"bad sync word at byte {pos} of {path}")
        pos += _EVENT.size
        channel = blob[pos:pos + channel_len].decode("ascii")
        pos += channel_len
        events.append((channel, blob[pos:pos + data_len]))
        pos += data_len
    return events
