"""A ROS message parser as the reader of fabkit's transform.yaml.

Usage:
  python ros_messages.py TYPE FILE
      Reads FILE (YAML, as `ros2 topic echo` prints a message) with PyYAML and builds the ROS 2
      message TYPE (e.g. geometry_msgs/msg/TransformStamped) from it with rosbags' ROS 2 Humble
      type store: every field of the message definition must be given, and no other (nested
      messages alike), each of its type (ints for integer fields, floats for float64). The
      message is then serialised to CDR and read back. Prints JSON: the message read back,
      nested as the definition is ({"header": {"stamp": {"sec", "nanosec"}, "frame_id"}, ...}).
      Exits 1 naming the field on a missing, extra or mistyped field.
"""
import json
import sys

import yaml
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Nodetype

INTS = {"int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64", "byte", "char"}


def build(store, msgtype, value, path):
    _, fields = store.fielddefs[msgtype]
    names = [n for n, _ in fields]
    if not isinstance(value, dict):
        sys.exit(f"{path or msgtype}: {value!r} is not a map of {names}")
    extra = sorted(set(value) - set(names))
    missing = [n for n in names if n not in value]
    if extra or missing:
        sys.exit(f"{path or msgtype}: fields {sorted(value)}; {msgtype} has {names}"
                 f" (missing {missing}, not in the definition {extra})")
    args = {}
    for name, (kind, sub) in fields:
        v, p = value[name], f"{path}.{name}" if path else name
        if kind == Nodetype.NAME:
            args[name] = build(store, sub, v, p)
        elif kind == Nodetype.BASE:
            t = sub[0]
            if t == "string":
                ok = isinstance(v, str)
            elif t in INTS:
                ok = isinstance(v, int) and not isinstance(v, bool)
            elif t in ("float32", "float64"):
                ok = isinstance(v, float)
            elif t == "bool":
                ok = isinstance(v, bool)
            else:
                ok = False
            if not ok:
                sys.exit(f"{p}: {v!r} is not a {t}")
            args[name] = v
        else:
            sys.exit(f"{p}: arrays and sequences are not needed here")
    return store.types[msgtype](**args)


def to_dict(store, msgtype, msg):
    _, fields = store.fielddefs[msgtype]
    return {n: to_dict(store, sub, getattr(msg, n)) if k == Nodetype.NAME else getattr(msg, n)
            for n, (k, sub) in fields}


def main():
    msgtype, path = sys.argv[1], sys.argv[2]
    store = get_typestore(Stores.ROS2_HUMBLE)
    with open(path, encoding="utf-8") as f:
        value = yaml.safe_load(f)
    msg = build(store, msgtype, value, "")
    back = store.deserialize_cdr(store.serialize_cdr(msg, msgtype), msgtype)
    json.dump(to_dict(store, msgtype, back), sys.stdout)


if __name__ == "__main__":
    main()
