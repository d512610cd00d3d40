#!/usr/bin/env python3
"""A robot's producer in Python: one real scan (OctoMap's own scan.dat.bz2, x y z per line,
sensor at the origin) published as a scan_t the way an organised cloud comes from a driver,
with NaN for no-returns (here every tenth point). The server drops and counts the NaN points
("non-finite" in its status) and applies the rest. README.md, "Connect your robot".
    publish_scan.py SCAN.dat.bz2 [LCM_URL] [ROBOT_ID]"""
import bz2
import sys
import time

import numpy as np

from octomap_rt import open_transport, scan_t
from octomap_rt.protocol_table import SCAN_CHANNEL_PREFIX


def main(path, url=None, robot="pyrobot"):
    points = np.loadtxt(bz2.open(path), dtype=np.float32).reshape(-1, 3)  # sensor frame [m]
    points[::10] = np.nan                          # no-returns, as organised clouds carry them
    msg = scan_t()
    msg.utime = int(time.time() * 1e6)             # acquisition time [us since the epoch]
    msg.seq = 0                                    # +1 per scan of this robot
    msg.sensor_position = [0.0, 0.0, 0.0]          # sensor origin in the map frame [m]
    msg.sensor_orientation = [1.0, 0.0, 0.0, 0.0]  # unit quaternion w, x, y, z: map <- sensor
    msg.max_range = -1.0                           # <= 0: the server's --max-range applies
    msg.points_frame = scan_t.POINTS_IN_SENSOR_FRAME
    msg.xyz = points.reshape(-1).tolist()
    msg.num_xyz = len(msg.xyz)
    msg.robot_id = robot                           # = the channel's suffix
    msg.map_frame = "map"
    open_transport(url).publish(SCAN_CHANNEL_PREFIX + robot.upper(), msg.encode())
    print(f"published {len(points)} points ({int(np.isnan(points[:, 0]).sum())} NaN) as {robot}")


if __name__ == "__main__":
    main(*sys.argv[1:])
