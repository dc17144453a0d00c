"""ROS 2 bags: written with mcap-ros2-support, read back; joint matching by name."""

import types

import numpy as np
import pytest
from mcap_ros2.writer import Writer

import robodyn as rd
from robodyn.measure.mcap_io import JOINT_STATE, MSGDEFS, POINT_STAMPED, write_mcap
from robodyn.robot.errors import RecordingError

POSE_DEF = ("std_msgs/Header header\ngeometry_msgs/Pose pose\n" + "=" * 80 + "\nMSG: std_msgs/Header\n"
            "builtin_interfaces/Time stamp\nstring frame_id\n" + "=" * 80 +
            "\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n" + "=" * 80 +
            "\nMSG: geometry_msgs/Pose\ngeometry_msgs/Point position\ngeometry_msgs/Quaternion "
            "orientation\n" + "=" * 80 + "\nMSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n"
            + "=" * 80 + "\nMSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n")


def _stamp(ns):
    return {"sec": ns // 10**9, "nanosec": ns % 10**9}


def _bag(path, names_per_msg, n_msgs=50, pose=False, joint_state=True):
    """A hand-written bag: JointState with the given (possibly shuffled) name order per message."""
    with path.open("wb") as fh:
        w = Writer(fh)
        js = w.register_msgdef(JOINT_STATE, MSGDEFS[JOINT_STATE])
        other = w.register_msgdef("geometry_msgs/msg/PoseStamped", POSE_DEF) if pose else None
        for k in range(n_msgs):
            ns = 1_700_000_000_000_000_000 + k * 2_000_000  # 2 ms
            names = names_per_msg[k % len(names_per_msg)]
            # the value of joint "jX" is X + k/1000 so that the order can be checked
            pos = [(int(name[1:]) if name[1:].isdigit() else 9) + k / 1000 for name in names]
            if joint_state:
                w.write_message("/joint_states", js, {
                    "header": {"stamp": _stamp(ns), "frame_id": ""}, "name": names,
                    "position": pos, "velocity": [], "effort": []}, log_time=ns, publish_time=ns)
            if pose:
                w.write_message("/tracker", other, {
                    "header": {"stamp": _stamp(ns + 500_000), "frame_id": "t"},
                    "pose": {"position": {"x": k, "y": 2.0, "z": 3.0},
                             "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}},
                    log_time=ns, publish_time=ns)
        w.finish()
    return path


def test_round_trip_identical(tmp_path):
    rng = np.random.default_rng(4)
    t = 1e-3 * np.arange(300)
    q = np.sin(np.outer(t, [1.0, 2.0]))
    qd = np.cos(np.outer(t, [1.0, 2.0])) * [1.0, 2.0]
    tau = rng.standard_normal((300, 2))
    rec = rd.Recording(t=t, q=q, qd=qd, tau=tau, joint_names=("a", "b"),
                       tool_t=0.004 * np.arange(60) + 0.0015, tool_points=rng.standard_normal((60, 3)))
    path = write_mcap(rec, tmp_path / "run.mcap", origin_ns=1_700_000_000_123_456_789)
    back = rd.read_recording(path)
    assert back.joint_names == ("a", "b") and back.estimated == frozenset({"qdd"})
    for field in ("q", "qd", "qdd", "tau", "tool_points"):
        assert np.array_equal(getattr(back, field), getattr(rec, field)), field
    # stamps are whole nanoseconds: times come back to within 0.5 ns
    assert np.abs(back.t - rec.t).max() < 1e-9
    assert np.abs(back.tool_t - rec.tool_t).max() < 1e-9


def test_robot_order_from_shuffled_messages(tmp_path):
    orders = [["j2", "j1", "j3", "finger"], ["j3", "finger", "j1", "j2"]]
    path = _bag(tmp_path / "shuffled.mcap", orders, pose=True)
    robot = types.SimpleNamespace(name="arm3", joint_names=("j1", "j2", "j3"))
    rec = rd.read_recording(path, robot=robot)
    assert rec.joint_names == ("j1", "j2", "j3")
    k = np.arange(50) / 1000
    assert np.allclose(rec.q, np.c_[1 + k, 2 + k, 3 + k], atol=1e-15)
    assert np.allclose(np.diff(rec.t), 2e-3) and rec.t[0] == 0.0
    assert rec.qd is not None and "qd" in rec.estimated and rec.tau is None
    assert np.allclose(rec.tool_t, rec.t + 0.5e-3) and np.allclose(rec.tool_points[:, 0], np.arange(50))


def test_bag_without_joint_state(tmp_path):
    path = _bag(tmp_path / "tracker_only.mcap", [["j1"]], pose=True, joint_state=False)
    with pytest.raises(RecordingError, match=r"tracker_only.mcap: no sensor_msgs/msg/JointState "
                                             r"messages \(the bag has: /tracker "
                                             r"\(geometry_msgs/msg/PoseStamped\)\)"):
        rd.read_recording(path)


def test_joint_names_not_matching_robot(tmp_path):
    path = _bag(tmp_path / "other.mcap", [["a1", "a2"]])
    robot = types.SimpleNamespace(name="arm2", joint_names=("j1", "a2"))
    with pytest.raises(RecordingError, match=r"other.mcap: /joint_states: joint names \['a1', 'a2'\] "
                                             r"do not match the robot 'arm2' \['j1', 'a2'\]: "
                                             r"missing \['j1'\]"):
        rd.read_recording(path, robot=robot)


def test_not_an_mcap_file(tmp_path):
    path = tmp_path / "fake.mcap"
    path.write_bytes(b"not a bag at all")
    with pytest.raises(RecordingError, match="fake.mcap: not a readable ROS 2 MCAP bag"):
        rd.read_recording(path)
    assert path.read_bytes() == b"not a bag at all"


def test_point_stamped_schema_is_what_we_write(tmp_path):
    assert MSGDEFS[POINT_STAMPED].startswith("std_msgs/Header header\ngeometry_msgs/Point point")


def _chunk_size_offsets(data: bytes) -> list[int]:
    """Byte offsets of every Chunk record's uncompressed_size field (MCAP: opcode 0x06, then
    length u64, start time u64, end time u64, uncompressed_size u64)."""
    out, i = [], 8  # after the magic
    while i + 9 <= len(data):
        op, length = data[i], int.from_bytes(data[i + 1:i + 9], "little")
        if op == 0x06:
            out.append(i + 9 + 16)
        i += 9 + length
    return out


def test_chunk_sizes_are_checked_before_decompression(tmp_path, monkeypatch):
    # issue 23: a damaged size field sized the decompression buffer (a 4 kB fuzzed bag allocated
    # 329 MiB); now the stated size must match the zstd frame, and the total the read limit
    rec = rd.Recording(t=np.arange(200) * 0.01, q=np.ones((200, 2)), joint_names=("a", "b"),
                       tau=np.zeros((200, 2)))
    good = write_mcap(rec, tmp_path / "good.mcap").read_bytes()
    offsets = _chunk_size_offsets(good)
    assert offsets
    bad = bytearray(good)
    bad[offsets[0]:offsets[0] + 8] = (300 * 2**20).to_bytes(8, "little")
    (tmp_path / "bad.mcap").write_bytes(bytes(bad))
    with pytest.raises(RecordingError, match=r"bad.mcap: a zstd chunk states 314572800 bytes but its "
                                             r"frame holds \d+: the bag is damaged"):
        rd.read_recording(tmp_path / "bad.mcap")
    stated = sum(int.from_bytes(good[o:o + 8], "little") for o in offsets)
    assert stated > 2 * len(good)  # zstd: the chunks expand past the file's size
    limit_mb = 1.5 * len(good) / 2**20  # reads the file, not what it expands to
    monkeypatch.setenv("ROBODYN_MAX_FILE_MB", repr(limit_mb))
    with pytest.raises(RecordingError, match=r"good.mcap: expands to more than .* MB when decompressed"):
        rd.read_recording(tmp_path / "good.mcap")
