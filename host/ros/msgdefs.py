"""ROS 2 message definitions (``.msg`` text) of the messages a recording carries, each type
once; :func:`schema_text` joins a type with everything it uses, the MCAP ``ros2msg`` schema
format (the type's text, then ``====...`` / ``MSG: pkg/Type`` / text per dependency).

The standard types are those of ROS 2 Jazzy (the tests compare their hashes with the
``rosbags`` type store); ``radar_array_processor_msgs/msg/FrameStatus`` is our own
(docs/ros.md says why and what each field means)."""

from __future__ import annotations

FRAME_STATUS = "radar_array_processor_msgs/msg/FrameStatus"
"""The per-frame status type (a small own schema, carried in the recording)."""

DEFINITIONS: dict[str, str] = {
    "builtin_interfaces/msg/Time": "int32 sec\nuint32 nanosec\n",
    "builtin_interfaces/msg/Duration": "int32 sec\nuint32 nanosec\n",
    "std_msgs/msg/Header": "builtin_interfaces/Time stamp\nstring frame_id\n",
    "std_msgs/msg/ColorRGBA": "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
    "geometry_msgs/msg/Point": "float64 x\nfloat64 y\nfloat64 z\n",
    "geometry_msgs/msg/Vector3": "float64 x\nfloat64 y\nfloat64 z\n",
    "geometry_msgs/msg/Quaternion": "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n",
    "geometry_msgs/msg/Pose": ("geometry_msgs/Point position\n"
                               "geometry_msgs/Quaternion orientation\n"),
    "geometry_msgs/msg/Transform": ("geometry_msgs/Vector3 translation\n"
                                    "geometry_msgs/Quaternion rotation\n"),
    "geometry_msgs/msg/TransformStamped": ("std_msgs/Header header\nstring child_frame_id\n"
                                           "geometry_msgs/Transform transform\n"),
    "tf2_msgs/msg/TFMessage": "geometry_msgs/TransformStamped[] transforms\n",
    "sensor_msgs/msg/PointField": (
        "uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\n"
        "uint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\n"
        "string name\nuint32 offset\nuint8 datatype\nuint32 count\n"),
    "sensor_msgs/msg/PointCloud2": (
        "std_msgs/Header header\nuint32 height\nuint32 width\n"
        "sensor_msgs/PointField[] fields\nbool is_bigendian\nuint32 point_step\n"
        "uint32 row_step\nuint8[] data\nbool is_dense\n"),
    "sensor_msgs/msg/CompressedImage": "std_msgs/Header header\nstring format\nuint8[] data\n",
    "visualization_msgs/msg/UVCoordinate": "float32 u\nfloat32 v\n",
    "visualization_msgs/msg/MeshFile": "string filename\nuint8[] data\n",
    "visualization_msgs/msg/Marker": (
        "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n"
        "int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n"
        "int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\n"
        "int32 ARROW_STRIP=12\nint32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n"
        "std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n"
        "geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n"
        "builtin_interfaces/Duration lifetime\nbool frame_locked\n"
        "geometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\n"
        "string texture_resource\nsensor_msgs/CompressedImage texture\n"
        "visualization_msgs/UVCoordinate[] uv_coordinates\nstring text\n"
        "string mesh_resource\nvisualization_msgs/MeshFile mesh_file\n"
        "bool mesh_use_embedded_materials\n"),
    "visualization_msgs/msg/MarkerArray": "visualization_msgs/Marker[] markers\n",
    FRAME_STATUS: (
        "std_msgs/Header header\nuint32 frame\nuint32 points\nbool complete\n"
        "uint32 missing_packets\nbool truncated\nuint32 detections\n"
        "float32 processing_time_ms\nstring[] problems\n"),
}


def _full_name(short: str) -> str:
    """``pkg/Type`` (as written in a field) -> ``pkg/msg/Type``."""
    pkg, _, name = short.rpartition("/")
    return short if "/msg/" in short else f"{pkg}/msg/{name}"


def _dependencies(typename: str, seen: list[str]) -> list[str]:
    """Types that ``typename`` uses, depth first, each once (appended to ``seen``)."""
    for line in DEFINITIONS[typename].splitlines():
        ftype = line.split()[0].split("[")[0]
        if "/" in ftype and "=" not in line:
            dep = _full_name(ftype)
            if dep not in seen:
                seen.append(dep)
                _dependencies(dep, seen)
    return seen


def schema_text(typename: str) -> str:
    """The MCAP ``ros2msg`` schema of ``typename`` (``pkg/msg/Type``): its definition and,
    after a line of 80 ``=``, ``MSG: pkg/Type`` and the definition of each type it uses."""
    parts = [DEFINITIONS[typename]]
    for dep in _dependencies(typename, []):
        short = dep.replace("/msg/", "/")
        parts.append(f"{'=' * 80}\nMSG: {short}\n{DEFINITIONS[dep]}")
    return "".join(parts)
