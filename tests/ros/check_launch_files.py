#!/usr/bin/python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Checks launch and .test files the way roslaunch would load them: XML,
arguments, included files, and that every node's package and executable can
be found (roslaunch.rlutil.check_roslaunch). Needs the pcl_ms package on
ROS_PACKAGE_PATH and the build's ros/ prefix on CMAKE_PREFIX_PATH."""
import sys

import roslaunch.rlutil


def main(paths):
    if not paths:
        print('usage: check_launch_files.py FILE.launch|FILE.test ...', file=sys.stderr)
        return 2
    failures = 0
    for path in paths:
        error = roslaunch.rlutil.check_roslaunch(path)
        if error:
            failures += 1
            print('%s: %s' % (path, error))
        else:
            print('%s: ok' % path)
    print('%d passed, %d failed' % (len(paths) - failures, failures))
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
