#!/usr/bin/env python3
"""Hostile peers for tools/hostile-mix-bench: for --duration seconds, on the LCM URL given,
send what the review found expensive (issue 21):
  - ray queries of 2000 rays through unknown space with max_range 10 km (ignore_unknown);
  - box queries of 1000 whole-map boxes;
  - floods of fresh-snapshot requests from 40 client ids;
  - far scans: 100 points 1 km from a sensor that jumps 3 km each scan, on 4 robot channels;
  - far400 scans: 100 points 400 m out (just under the server's mean-ray bound at 0.1 m), 4 a
    second from a sensor that stays put, each from a robot id it has not used for a while
    (50 ids in turn: the server's --max-producers is 64).
--kinds picks some of them (rays, boxes, fresh, far, far400; default all but far400). Prints what it sent, one
`key value` a line, when the time is up or on SIGTERM."""
import argparse
import math
import random
import signal
import time

from octomap_rt import (box_query_t, map_request_t, ray_query_t, scan_t)
from octomap_rt.channels import Channels
from octomap_rt.protocol_table import MAX_QUERY_RAYS
from octomap_rt.transport import open_transport

CHANNELS = Channels()  # the protocol's names (protocol/channels.h) in $OCTOMAP_RT_NAMESPACE, as the server takes them


def ray_query(i):
    q = ray_query_t()
    q.request_id, q.client_id, q.reply_channel = i, "hostile-rays", "HOSTILE_REPLY"
    q.wait_seq, q.ignore_unknown, q.max_range = -1, 1, 10000.0
    n = MAX_QUERY_RAYS  # the most a ray query may have
    q.origin_xyz = [0.05, 0.05, 0.25] * n
    q.direction_xyz = [c for k in range(n) for c in (1.0, 0.001 * k, 0.3)]
    q.num_xyz = 3 * n
    return q


def box_query(i):
    q = box_query_t()
    q.request_id, q.client_id, q.reply_channel = i, "hostile-boxes", "HOSTILE_REPLY"
    q.wait_seq, q.mode = -1, box_query_t.MODE_COUNTS
    q.boxes = [-1000.0, -1000.0, -1000.0, 1000.0, 1000.0, 1000.0] * 1000
    q.num_values = len(q.boxes)
    return q


def fresh_request(i, client):
    r = map_request_t()
    r.utime, r.request_id, r.snapshot_id, r.format = int(time.time() * 1e6), i, -1, 1
    r.client_id = client
    r.reply_channel = CHANNELS.reply_channel(CHANNELS.map_reply_prefix, client)
    r.chunk_indices, r.num_chunk_indices = [], 0
    return r


def far_scan(seq, robot, distance=1000.0, jump=3000.0):
    s = scan_t()
    s.utime, s.seq, s.robot_id = int(time.time() * 1e6), seq, robot
    s.sensor_position = [jump * (seq % 7), 2.0, 0.5]
    s.sensor_orientation = [1.0, 0.0, 0.0, 0.0]
    s.points_frame, s.max_range = scan_t.POINTS_IN_SENSOR_FRAME, -1.0
    s.map_frame = "map"
    rng = random.Random(seq)
    xyz = []
    for _ in range(100):
        d = [rng.gauss(0, 1) for _ in range(3)]
        n = math.sqrt(sum(c * c for c in d)) or 1.0
        xyz += [distance * c / n for c in d]
    s.xyz, s.num_xyz = xyz, len(xyz)
    return s


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lcm-url", required=True)
    ap.add_argument("--duration", type=float, default=30)
    ap.add_argument("--kinds", default="rays,boxes,fresh,far")
    a = ap.parse_args()
    kinds = set(a.kinds.split(","))
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    t = open_transport(a.lcm_url)
    sent = {"ray_queries": 0, "box_queries": 0, "fresh_requests": 0, "far_scans": 0, "far400_scans": 0}
    rays, boxes = ray_query(0), box_query(0)
    end, i, seq = time.monotonic() + a.duration, 0, 0
    while time.monotonic() < end and not stop:
        i += 1
        rays.request_id = boxes.request_id = i
        if "rays" in kinds:
            t.publish(CHANNELS.query_rays, rays.encode())
            sent["ray_queries"] += 1
        if "boxes" in kinds:
            t.publish(CHANNELS.query_boxes, boxes.encode())
            sent["box_queries"] += 1
        if i % 2 == 0 and "fresh" in kinds:
            for c in range(40):
                t.publish(CHANNELS.map_request, fresh_request(i * 100 + c, "hostile-%d" % c).encode())
                sent["fresh_requests"] += 1
        if i % 4 == 0 and "far" in kinds:
            for r in range(4):
                robot = "evil%d" % r
                t.publish(CHANNELS.scan_prefix + robot.upper(), far_scan(seq, robot).encode())
                sent["far_scans"] += 1
            seq += 1
        if i % 5 == 0 and "far400" in kinds:
            k = sent["far400_scans"]
            robot = "fresh%d" % (k % 50)
            t.publish("OCTOMAP_RT_SCAN_" + robot.upper(), far_scan(k, robot, 400.0, 0.0).encode())
            sent["far400_scans"] += 1
        t.handle(0.0)
        time.sleep(0.05)
    for k, v in sent.items():
        print(k, v, flush=True)


if __name__ == "__main__":
    main()
