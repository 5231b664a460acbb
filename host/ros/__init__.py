"""ROS 2 interop of the host: the point cloud, the GNN objects, the radar mount and a per-frame
status as ROS 2 messages (:mod:`host.ros.messages`, definitions in :mod:`host.ros.msgdefs`),
written to MCAP recordings (:mod:`host.ros.recording`) and summarised or read back
(:mod:`host.ros.summary`). Field names, units and topics: docs/ros.md.

Everything here takes plain data (a ``host.pointcloud.PointCloud``, the GNN objects as the
dicts of ``gnn.infer.detect_objects``, numbers): no ROS installation is needed."""
