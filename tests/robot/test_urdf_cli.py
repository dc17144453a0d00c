"""``robodyn ... --tool LINK``: the end-effector link of a URDF file from the command line."""

from __future__ import annotations

from pathlib import Path

import pytest

from robodyn.cli import main

UR5 = Path(__file__).resolve().parent / "fixtures" / "ur5_ros_industrial.urdf"


def test_show_with_tool_link(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", str(UR5)]) == 0
    assert "tool: identity" in capsys.readouterr().out  # ee_link and tool0 branch: last link
    assert main(["show", str(UR5), "--tool", "tool0"]) == 0
    out = capsys.readouterr().out
    # tool0 is 0.0823 m along y of wrist_3_link, turned -90 deg about x
    assert "tool: 1 0 0 0; 0 1.79489651492081e-9 1.0 0.0823; 0 -1.0 1.79489651492081e-9 0" in out


def test_unknown_tool_link_is_exit_2_with_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", str(UR5), "--tool", "gripper"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert err.startswith("robodyn: error: ")
    assert "ur5_ros_industrial.urdf: tool link 'gripper' is not a link of the file" in err


def test_tool_on_a_builtin_is_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", "puma560", "--tool", "tool0"]) == 2
    assert "puma560: tool='tool0' selects a link of a URDF file" in capsys.readouterr().err


@pytest.mark.parametrize("command", ["derive", "check", "codegen", "export", "simulate",
                                     "calibrate"])
def test_every_robot_command_takes_tool(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main([command, "--help"])
    assert "--tool LINK" in capsys.readouterr().out
