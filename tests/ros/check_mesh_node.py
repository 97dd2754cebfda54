#!/usr/bin/python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""rostest client for the pcl_ms node and nodelet (tests/ros/*.test).

Publishes clouds on the node's input topic and checks what comes back on
mesh, mesh_marker and boundary_marker: the bunny, an organized colour frame
with NaNs, then bad clouds (empty, all NaN, collinear, no z field, data
shorter than the sizes), each of which must be refused with an ERROR on
/rosout while the node lives on and meshes the next good cloud.
"""
import math
import struct
import sys
import threading
import unittest

import rospy
import rostest
from pcl_msgs.msg import PolygonMesh
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import PointCloud2, PointField
from visualization_msgs.msg import Marker

MESH_TIMEOUT = 120.0  # seconds; the bunny takes about one on our machines
ERROR_TIMEOUT = 20.0


def read_bunny_points(path):
    """x y z of a binary PCD file whose fields are exactly x y z float32."""
    with open(path, 'rb') as stream:
        header = {}
        while True:
            line = stream.readline().decode('ascii').strip()
            key, _, value = line.partition(' ')
            header[key] = value
            if key == 'DATA':
                break
        if header['FIELDS'] != 'x y z' or header['DATA'] != 'binary':
            raise ValueError('%s: expected binary x y z, got %s' % (path, header))
        count = int(header['POINTS'])
        values = struct.unpack('<%df' % (3 * count), stream.read(12 * count))
    return [values[3 * i:3 * i + 3] for i in range(count)]


def make_cloud(points, frame_id, stamp, width=None, height=1, colors=None):
    """PointCloud2 with x y z (and a packed rgb float when colors is given)."""
    cloud = PointCloud2()
    cloud.header.frame_id = frame_id
    cloud.header.stamp = stamp
    cloud.height = height
    cloud.width = len(points) // height if width is None else width
    cloud.fields = [PointField(name, 4 * i, PointField.FLOAT32, 1)
                    for i, name in enumerate('xyz')]
    if colors is not None:
        cloud.fields.append(PointField('rgb', 12, PointField.FLOAT32, 1))
    cloud.point_step = 16 if colors is not None else 12
    cloud.row_step = cloud.point_step * cloud.width
    cloud.is_bigendian = False
    cloud.is_dense = all(all(math.isfinite(v) for v in p) for p in points)
    data = bytearray()
    for i, point in enumerate(points):
        data += struct.pack('<3f', *point)
        if colors is not None:
            data += struct.pack('<I', colors[i])
    cloud.data = bytes(data)
    return cloud


def organized_frame(width=64, height=48):
    """A wavy surface seen by a depth camera along +z, a disc of NaN pixels
    (as occlusions leave), each pixel coloured by its column and row."""
    points, colors = [], []
    for row in range(height):
        for column in range(width):
            u = (column - width / 2) * 0.01
            v = (row - height / 2) * 0.01
            depth = 1.0 + 0.05 * math.sin(10 * u) * math.cos(8 * v)
            if (u - 0.1) ** 2 + v ** 2 < 0.01:
                points.append((math.nan, math.nan, math.nan))
            else:
                points.append((u * depth, v * depth, depth))
            colors.append((column * 4) << 16 | (row * 5) << 8 | 200)
    return points, colors


def non_manifold_edges(polygons):
    uses = {}
    for polygon in polygons:
        v = polygon.vertices
        for a, b in ((v[0], v[1]), (v[1], v[2]), (v[2], v[0])):
            key = (min(a, b), max(a, b))
            uses[key] = uses.get(key, 0) + 1
    return sum(1 for count in uses.values() if count > 2)


class MeshNodeTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('check_mesh_node')
        cls.namespace = rospy.get_param('~mesh_ns').rstrip('/')
        cls.data_dir = rospy.get_param('~data_dir')
        cls.lock = threading.Condition()
        cls.received = {'mesh': [], 'mesh_marker': [], 'boundary_marker': []}
        cls.errors = []
        cls.drop_warnings = []
        # Clouds sent, and clouds the node reported done (meshed or refused):
        # it logs after it is free for the next, so waiting for the report
        # keeps skip_if_busy from dropping a cloud the test did not mean to.
        cls.sent = 0
        cls.finished = 0
        cls.skip_if_busy = rospy.get_param('~skip_if_busy')
        cls.publisher = rospy.Publisher(rospy.get_param('~input'), PointCloud2, queue_size=10)
        rospy.Subscriber(cls.namespace + '/mesh', PolygonMesh, cls.on_message, 'mesh')
        rospy.Subscriber(cls.namespace + '/mesh_marker', Marker, cls.on_message, 'mesh_marker')
        rospy.Subscriber(cls.namespace + '/boundary_marker', Marker, cls.on_message,
                         'boundary_marker')
        rospy.Subscriber('/rosout', Log, cls.on_log)
        deadline = rospy.Time.now() + rospy.Duration(60)
        while cls.publisher.get_num_connections() == 0 and rospy.Time.now() < deadline:
            rospy.sleep(0.1)
        if cls.publisher.get_num_connections() == 0:
            raise AssertionError('the node never subscribed to the input topic')
        rospy.sleep(1.0)  # let the /rosout and output connections settle too

    @classmethod
    def on_message(cls, message, topic):
        with cls.lock:
            cls.received[topic].append(message)
            cls.lock.notify_all()

    @classmethod
    def on_log(cls, log):
        with cls.lock:
            if log.level == Log.INFO and 'mesh published' in log.msg:
                cls.finished += 1
            elif log.level >= Log.ERROR and 'not meshed' in log.msg:
                cls.errors.append(log.msg)
                cls.finished += 1
            elif log.level == Log.WARN and 'skip_if_busy: dropped' in log.msg:
                cls.drop_warnings.append(log.msg)
            cls.lock.notify_all()

    def wait_for(self, topic, stamp, timeout=MESH_TIMEOUT):
        """The message on topic whose header carries stamp."""
        def find():
            return next((m for m in self.received[topic] if m.header.stamp == stamp), None)
        with self.lock:
            self.lock.wait_for(lambda: find() is not None or rospy.is_shutdown(), timeout)
            message = find()
        self.assertIsNotNone(message, 'no %s for the cloud of %s' % (topic, stamp.to_sec()))
        return message

    def publish(self, cloud):
        """Sends cloud once the node has reported on every earlier one."""
        with self.lock:
            self.lock.wait_for(lambda: self.finished >= self.sent or rospy.is_shutdown(),
                               MESH_TIMEOUT)
            self.assertGreaterEqual(self.finished, self.sent, 'the node went silent')
            self.sent += 1
        self.publisher.publish(cloud)

    def mesh_cloud(self, cloud):
        self.publish(cloud)
        stamp = cloud.header.stamp
        return (self.wait_for('mesh', stamp), self.wait_for('mesh_marker', stamp),
                self.wait_for('boundary_marker', stamp))

    def check_mesh(self, cloud, mesh, mesh_marker, boundary_marker):
        self.assertEqual(mesh.header.frame_id, cloud.header.frame_id)
        self.assertEqual(mesh_marker.header.frame_id, cloud.header.frame_id)
        self.assertEqual(boundary_marker.header.frame_id, cloud.header.frame_id)
        # The mesh carries the input cloud unchanged: every field, every byte.
        self.assertEqual([f.name for f in mesh.cloud.fields], [f.name for f in cloud.fields])
        self.assertEqual((mesh.cloud.width, mesh.cloud.height), (cloud.width, cloud.height))
        self.assertEqual(bytes(mesh.cloud.data), bytes(cloud.data))
        count = cloud.width * cloud.height
        for polygon in mesh.polygons:
            self.assertEqual(len(polygon.vertices), 3)
            self.assertTrue(all(0 <= v < count for v in polygon.vertices), polygon.vertices)
        self.assertEqual(non_manifold_edges(mesh.polygons), 0)
        self.assertEqual(mesh_marker.type, Marker.TRIANGLE_LIST)
        self.assertEqual(len(mesh_marker.points), 3 * len(mesh.polygons))
        self.assertEqual(boundary_marker.type, Marker.LINE_LIST)
        self.assertEqual((boundary_marker.color.r, boundary_marker.color.g,
                          boundary_marker.color.b), (0.0, 0.0, 1.0))
        self.assertEqual(len(boundary_marker.points) % 2, 0)

    def test_1_bunny(self):
        points = read_bunny_points(self.data_dir + '/bunny.pcd')
        cloud = make_cloud(points, 'bunny_frame', rospy.Time(1001))
        mesh, mesh_marker, boundary_marker = self.mesh_cloud(cloud)
        self.check_mesh(cloud, mesh, mesh_marker, boundary_marker)
        # The reference surface of these points has 69,451 triangles.
        self.assertGreater(len(mesh.polygons), 68000)
        self.assertEqual(mesh_marker.colors, [])  # no rgb field: one marker colour
        # Five openings in the base: boundary edges, two points each.
        self.assertGreater(len(boundary_marker.points), 2 * 5 * 3)
        first = mesh.polygons[0].vertices[0]
        self.assertAlmostEqual(mesh_marker.points[0].x, points[first][0], places=6)

    def test_2_organized_frame_with_nans(self):
        points, colors = organized_frame()
        cloud = make_cloud(points, 'camera_frame', rospy.Time(1002), width=64, height=48,
                           colors=colors)
        finite = [all(math.isfinite(v) for v in p) for p in points]
        self.assertLess(sum(finite), len(points))  # the NaN disc is there
        mesh, mesh_marker, boundary_marker = self.mesh_cloud(cloud)
        self.check_mesh(cloud, mesh, mesh_marker, boundary_marker)
        # A height field of n points has about 2n triangles.
        self.assertGreater(len(mesh.polygons), 1.5 * sum(finite))
        self.assertGreaterEqual(len(boundary_marker.points), 2 * 3)
        self.assertEqual(len(mesh_marker.colors), len(mesh_marker.points))
        # The surface faces the viewpoint: the parameter when the .test sets
        # one, else the camera frame's origin (organized cloud). A few
        # triangles on steep slopes face away from any one point.
        viewpoint = rospy.get_param('~viewpoint', [0.0, 0.0, 0.0])
        facing = 0
        for polygon in mesh.polygons:
            a, b, c = (points[i] for i in polygon.vertices)
            ab = [b[k] - a[k] for k in range(3)]
            ac = [c[k] - a[k] for k in range(3)]
            normal = [ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2],
                      ab[0] * ac[1] - ab[1] * ac[0]]
            to_triangle = [(a[k] + b[k] + c[k]) / 3 - viewpoint[k] for k in range(3)]
            facing += sum(normal[k] * to_triangle[k] for k in range(3)) < 0
        self.assertGreater(facing, 0.95 * len(mesh.polygons),
                           'triangles facing the viewpoint %s' % viewpoint)
        for t, polygon in enumerate(mesh.polygons):
            for corner, index in enumerate(polygon.vertices):
                self.assertTrue(finite[index], 'triangle %d uses NaN pixel %d' % (t, index))
                color = mesh_marker.colors[3 * t + corner]
                rgb = colors[index]
                self.assertEqual((round(color.r * 255), round(color.g * 255),
                                  round(color.b * 255)),
                                 ((rgb >> 16) & 255, (rgb >> 8) & 255, rgb & 255))

    def test_3_bad_clouds_are_refused_and_the_node_lives_on(self):
        nan = math.nan
        empty = make_cloud([], 'bad', rospy.Time(2001))
        all_nan = make_cloud([(nan, nan, nan)] * 50, 'bad', rospy.Time(2002), width=10, height=5)
        collinear = make_cloud([(i, 2 * i, 3 * i) for i in range(20)], 'bad', rospy.Time(2003))
        no_z = make_cloud([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], 'bad', rospy.Time(2004))
        no_z.fields = no_z.fields[:2]
        short_data = make_cloud([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], 'bad',
                                rospy.Time(2005))
        short_data.data = short_data.data[:-12]
        cases = [(empty, 'empty'), (all_nan, ''), (collinear, ''), (no_z, "no 'z' field"),
                 (short_data, 'bytes')]
        for cloud, reason in cases:
            with self.lock:
                errors_before = len(self.errors)
            self.publish(cloud)
            with self.lock:
                self.lock.wait_for(lambda: len(self.errors) > errors_before, ERROR_TIMEOUT)
                new_errors = self.errors[errors_before:]
            self.assertEqual(len(new_errors), 1,
                             'cloud of %s: expected one ERROR' % cloud.header.stamp.to_sec())
            self.assertIn('%.3f' % cloud.header.stamp.to_sec(), new_errors[0])
            self.assertIn(reason, new_errors[0])
        # Still alive: the next good cloud is meshed.
        points, colors = organized_frame(32, 24)
        cloud = make_cloud(points, 'camera_frame', rospy.Time(2006), width=32, height=24,
                           colors=colors)
        mesh, mesh_marker, boundary_marker = self.mesh_cloud(cloud)
        self.check_mesh(cloud, mesh, mesh_marker, boundary_marker)
        self.assertGreater(len(mesh.polygons), 500)
        with self.lock:
            stamps = [m.header.stamp.secs for m in self.received['mesh']]
        self.assertFalse(any(2001 <= s <= 2005 for s in stamps),
                         'a bad cloud produced a mesh: %s' % stamps)

    def test_4_cloud_arriving_while_meshing(self):
        """With skip_if_busy the second of two quick clouds is dropped and the
        log says so; without it, it waits in the queue and is meshed next."""
        bunny = make_cloud(read_bunny_points(self.data_dir + '/bunny.pcd'), 'bunny_frame',
                           rospy.Time(3001))
        points, colors = organized_frame()
        frame = make_cloud(points, 'camera_frame', rospy.Time(3002), width=64, height=48,
                           colors=colors)
        self.publish(bunny)
        rospy.sleep(0.2)  # the bunny takes about a second: the frame arrives meanwhile
        self.publisher.publish(frame)  # on purpose without waiting
        self.wait_for('mesh', bunny.header.stamp)
        if self.skip_if_busy:
            with self.lock:
                self.lock.wait_for(lambda: self.drop_warnings, ERROR_TIMEOUT)
                warnings = list(self.drop_warnings)
            self.assertEqual(len(warnings), 1, warnings)
            self.assertIn('%.3f' % frame.header.stamp.to_sec(), warnings[0])
            rospy.sleep(3.0)
            with self.lock:
                stamps = [m.header.stamp for m in self.received['mesh']]
            self.assertNotIn(frame.header.stamp, stamps)
        else:
            self.wait_for('mesh', frame.header.stamp)
            self.assertEqual(self.drop_warnings, [])


if __name__ == '__main__':
    rostest.rosrun('pcl_ms', 'check_mesh_node', MeshNodeTest, sys.argv)
