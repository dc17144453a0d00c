"""Measured data in: recordings, file readers, sensor conversion, filtering and differentiation.

``Recording`` holds one validated run; ``read_recording`` reads CSV/TSV (optionally gzip) through a
recording spec, or a ROS 2 bag (MCAP) of ``sensor_msgs/JointState`` messages.
"""

from robodyn.measure.read import read_recording
from robodyn.measure.recording import Recording

__all__ = ["Recording", "read_recording"]
