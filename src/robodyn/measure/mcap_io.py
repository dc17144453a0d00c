"""ROS 2 bags (MCAP): ``sensor_msgs/msg/JointState`` joints and a point tracker, read and written.

Read and written with the ``mcap`` and ``mcap-ros2-support`` packages (no ROS installation).
Time comes from the header stamps (integer nanoseconds), made relative to the first JointState
stamp; tracker stamps (``geometry_msgs/msg/PointStamped`` or ``PoseStamped``) share that origin.
Each JointState message may list its joints in any order; they are matched by name.
"""

from __future__ import annotations

import io
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from robodyn.extras import require
from robodyn.measure.csv_io import max_file_bytes
from robodyn.measure.recording import Recording
from robodyn.robot.errors import RecordingError

__all__ = ["MSGDEFS", "read_mcap", "write_mcap"]

JOINT_STATE = "sensor_msgs/msg/JointState"
POINT_STAMPED = "geometry_msgs/msg/PointStamped"
POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
_SEP = "=" * 80

_TIME = "int32 sec\nuint32 nanosec\n"
_HEADER = "builtin_interfaces/Time stamp\nstring frame_id\n"
_POINT = "float64 x\nfloat64 y\nfloat64 z\n"
# ROS 2 message definitions, dependencies appended after '=' separator lines (the .msg texts)
MSGDEFS = {
    JOINT_STATE: ("std_msgs/Header header\n\nstring[] name\nfloat64[] position\nfloat64[] velocity\n"
                  f"float64[] effort\n{_SEP}\nMSG: std_msgs/Header\n{_HEADER}{_SEP}\n"
                  f"MSG: builtin_interfaces/Time\n{_TIME}"),
    POINT_STAMPED: (f"std_msgs/Header header\ngeometry_msgs/Point point\n{_SEP}\n"
                    f"MSG: std_msgs/Header\n{_HEADER}{_SEP}\nMSG: builtin_interfaces/Time\n{_TIME}"
                    f"{_SEP}\nMSG: geometry_msgs/Point\n{_POINT}"),
}


def _stamp(msg: Any) -> int:
    """Header stamp in integer nanoseconds."""
    return int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)


def _check_chunks(data: bytes, limit: int, name: str) -> None:
    """Refuse a bag whose chunks would decompress beyond ``limit`` bytes in all, or whose chunk
    states a size its data contradicts (a damaged or hostile length field would otherwise size
    the decompression buffer): before any chunk is decompressed."""
    Chunk = require("mcap.records", f"reading the ROS 2 bag {name}").Chunk  # noqa: N806
    StreamReader = require("mcap.stream_reader", f"reading the ROS 2 bag {name}").StreamReader  # noqa: N806

    total = 0
    for record in StreamReader(io.BytesIO(data), emit_chunks=True, record_size_limit=len(data)).records:
        if not isinstance(record, Chunk):
            continue
        stated = record.uncompressed_size
        if record.compression == "" and stated != len(record.data):
            raise RecordingError(f"{name}: a chunk states {stated} bytes but holds {len(record.data)}")
        if record.compression == "zstd":
            zstandard = require("zstandard", f"reading the ROS 2 bag {name}")
            real = zstandard.frame_content_size(record.data)
            if real >= 0 and real != stated:
                raise RecordingError(f"{name}: a zstd chunk states {stated} bytes but its frame "
                                     f"holds {real}: the bag is damaged")
        total += stated
        if total > limit:
            raise RecordingError(f"{name}: expands to more than {limit / 2**20:g} MB when "
                                 "decompressed (set ROBODYN_MAX_FILE_MB to read it)")


def _messages(p: Path, joint_topic: str | None, tool_topic: str | None,
              ) -> tuple[list[tuple[int, list[str], Any, Any, Any, str]],
                         dict[str, list[tuple[int, tuple[float, float, float]]]], dict[str, str]]:
    """The bag's JointState messages (stamp, names, position, velocity, effort, topic), tracker
    points by topic and every topic's message type; a damaged or oversized bag is refused."""
    make_reader = require("mcap.reader", f"reading the ROS 2 bag {p}").make_reader
    DecoderFactory = require("mcap_ros2.decoder", f"reading the ROS 2 bag {p}").DecoderFactory  # noqa: N806
    joints: list[tuple[int, list[str], Any, Any, Any, str]] = []
    tool: dict[str, list[tuple[int, tuple[float, float, float]]]] = {}
    topics: dict[str, str] = {}
    limit = max_file_bytes()
    if p.stat().st_size > limit:
        raise RecordingError(f"{p.name}: {p.stat().st_size / 2**20:.1f} MB, more than the "
                             f"{limit / 2**20:g} MB read (set ROBODYN_MAX_FILE_MB to read it)")
    # in memory: a damaged length field then reads what is there instead of allocating what it says
    data = p.read_bytes()
    try:
        _check_chunks(data, limit, p.name)
        with io.BytesIO(data) as fh:
            reader = make_reader(fh, validate_crcs=True, decoder_factories=[DecoderFactory()])
            for schema, channel, _, msg in reader.iter_decoded_messages(log_time_order=True):
                kind, topic = schema.name, channel.topic
                topics[topic] = kind
                if kind == JOINT_STATE and (joint_topic is None or topic == joint_topic):
                    joints.append((_stamp(msg), list(msg.name), msg.position, msg.velocity, msg.effort,
                                   topic))
                elif kind in (POINT_STAMPED, POSE_STAMPED) and (tool_topic is None or topic == tool_topic):
                    pt = msg.point if kind == POINT_STAMPED else msg.pose.position
                    tool.setdefault(topic, []).append((_stamp(msg), (pt.x, pt.y, pt.z)))
    except RecordingError:
        raise
    except Exception as exc:  # noqa: BLE001 - McapError, and any failure of the third-party
        # decoders on a damaged file (zstd/lz4 chunk errors, struct.error, an overflowing length
        # field, mcap_ros2's schema-parser errors), is a property of the file, reported as such
        raise RecordingError(f"{p.name}: not a readable ROS 2 MCAP bag ({type(exc).__name__}: "
                             f"{' '.join(str(exc).split())})") from None
    return joints, tool, topics


def read_mcap(path: str | PathLike[str], robot: Any = None, joint_topic: str | None = None,
              tool_topic: str | None = None) -> Recording:
    """Read a ROS 2 bag: joints from ``sensor_msgs/msg/JointState``, a tracker from points/poses.

    Parameters
    ----------
    path : str or path
        ``.mcap`` file (only read).
    robot : Robot, optional
        Every robot joint must appear in the messages (others, e.g. gripper fingers, are left
        out); the recording's joints are in the robot's chain order. Without a robot, the order
        of the first message.
    joint_topic, tool_topic : str, optional
        Topics to use when a bag has several of a kind.

    Returns
    -------
    Recording
        ``q`` from ``position``; ``qd`` from ``velocity`` and ``tau`` from ``effort`` when the
        messages carry them; ``tool_t``/``tool_points`` from the tracker topic.
    """
    p = Path(path)
    joints, tool, topics = _messages(p, joint_topic, tool_topic)
    if not joints:
        listed = ", ".join(f"{t} ({k})" for t, k in topics.items()) or "no messages"
        which = f" on topic {joint_topic!r}" if joint_topic else ""
        raise RecordingError(f"{p.name}: no {JOINT_STATE} messages{which} (the bag has: {listed})")
    joint_topics = sorted({j[5] for j in joints})
    if len(joint_topics) > 1:
        raise RecordingError(f"{p.name}: JointState on several topics {joint_topics}; pick one with "
                             "joint_topic=")
    if len(tool) > 1:
        raise RecordingError(f"{p.name}: tracker points on several topics {sorted(tool)}; pick one "
                             "with tool_topic=")
    first = joints[0][1]
    names = tuple(robot.joint_names) if robot is not None else tuple(first)
    if robot is not None:
        missing = [j for j in names if j not in first]
        if missing:
            raise RecordingError(f"{p.name}: {joint_topics[0]}: joint names {first} do not match the "
                                 f"robot {robot.name!r} {list(names)}: missing {missing}")
    n, count = len(names), len(joints)
    stamps = np.empty(count, dtype=np.int64)
    arrays = {key: np.full((count, n), np.nan) for key in ("position", "velocity", "effort")}
    has = {"velocity": True, "effort": True}
    for row, (stamp, msg_names, pos, vel, eff, _) in enumerate(joints):
        stamps[row] = stamp
        index = {name: k for k, name in enumerate(msg_names)}
        try:
            cols = [index[name] for name in names]
        except KeyError as exc:
            raise RecordingError(f"{p.name}: {joint_topics[0]}: message {row} (stamp {stamp} ns) has "
                                 f"no joint {exc.args[0]!r} (it names {msg_names})") from None
        for key, values in (("position", pos), ("velocity", vel), ("effort", eff)):
            if key != "position" and len(values) == 0:
                has[key] = False
                continue
            if len(values) != len(msg_names):
                raise RecordingError(f"{p.name}: {joint_topics[0]}: message {row} (stamp {stamp} ns): "
                                     f"{len(values)} {key} values for {len(msg_names)} names")
            arrays[key][row] = np.asarray(values, dtype=float)[cols]
    origin = int(stamps[0])
    t = (stamps - origin) / 1e9  # integer ns relative to the first stamp, then seconds
    kw: dict[str, Any] = {}
    if tool:
        samples = next(iter(tool.values()))
        kw["tool_t"] = (np.array([s for s, _ in samples], dtype=np.int64) - origin) / 1e9
        kw["tool_points"] = np.array([xyz for _, xyz in samples], dtype=float)
    units = {"t": f"s since the first JointState stamp ({origin} ns)"}
    return Recording(t=t, q=arrays["position"], qd=arrays["velocity"] if has["velocity"] else None,
                     tau=arrays["effort"] if has["effort"] else None, joint_names=names,
                     units=units, source=p.name, **kw)


def _ns(seconds: np.ndarray, origin_ns: int) -> np.ndarray:
    return origin_ns + np.round(np.asarray(seconds) * 1e9).astype(np.int64)


def _header(ns: int, frame: str) -> dict[str, Any]:
    return {"stamp": {"sec": int(ns // 1_000_000_000), "nanosec": int(ns % 1_000_000_000)},
            "frame_id": frame}


def write_mcap(rec: Recording, path: str | PathLike[str], *, joint_topic: str = "/joint_states",
               tool_topic: str = "/tracker/point", origin_ns: int = 0) -> Path:
    """Write a recording as a ROS 2 bag: JointState (position; velocity and effort when measured).

    Parameters
    ----------
    rec : Recording
    path : str or path
        ``.mcap`` file to write.
    joint_topic, tool_topic : str
        Topic names; tool points go out as ``geometry_msgs/msg/PointStamped``.
    origin_ns : int
        Stamp of ``t = 0``, ns (``t`` is rounded to whole nanoseconds).

    Returns
    -------
    Path
    """
    Writer = require("mcap_ros2.writer", "writing a ROS 2 bag (MCAP)").Writer  # noqa: N806

    p = Path(path)
    velocity = rec.qd is not None and "qd" not in rec.estimated
    with p.open("wb") as fh:
        writer = Writer(fh)
        js = writer.register_msgdef(JOINT_STATE, MSGDEFS[JOINT_STATE])
        names = list(rec.joint_names)
        for k, ns in enumerate(_ns(rec.t, origin_ns)):
            msg = {"header": _header(int(ns), "base"), "name": names,
                   "position": rec.q[k].tolist(),
                   "velocity": rec.qd[k].tolist() if velocity else [],
                   "effort": rec.tau[k].tolist() if rec.tau is not None else []}
            writer.write_message(joint_topic, js, msg, log_time=int(ns), publish_time=int(ns))
        if rec.tool_t is not None:
            ps = writer.register_msgdef(POINT_STAMPED, MSGDEFS[POINT_STAMPED])
            for k, ns in enumerate(_ns(rec.tool_t, origin_ns)):
                x, y, z = (float(v) for v in rec.tool_points[k])
                writer.write_message(tool_topic, ps, {"header": _header(int(ns), "tracker"),
                                                      "point": {"x": x, "y": y, "z": z}},
                                     log_time=int(ns), publish_time=int(ns))
        writer.finish()
    return p
