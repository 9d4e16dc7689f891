"""Reading and writing rosbag2 bags with ``rosbags``: the replay's view of a bag.

The input side opens a bag (a directory or one ``.mcap``), turns every
reading problem into :class:`~fastsim_ros.replay.errors.BadInput`, and
gives the definition of each input connection so it can be copied as it
is; the output side makes the writer (rosbag2 version 9, MCAP, zstd chunk
compression) and the node's publisher QoS of the output connections.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import yaml
from rosbags.interfaces import (Qos, QosDurability, QosHistory, QosLiveliness,
                                QosReliability, QosTime)
from rosbags.rosbag2 import Reader, Writer
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode, StoragePlugin
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from fastsim_ros.replay.errors import BadInput, problem

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)


class _LibYaml:
    """Stand-in for ruamel's ``YAML(typ='safe')`` inside rosbags, on PyYAML's libyaml.

    Without ruamel's C extension (not a dependency here) rosbags spends
    about 12 ms per output connection and 0.1-0.2 s per bag dumping and
    loading its small YAML documents (QoS profiles, ``metadata.yaml``):
    more than replaying a 4 s bag.  Same documents, parsed by the same
    readers (the tests open every output with the unpatched rosbags reader).
    """

    _LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    _DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.default_flow_style: bool | None = False

    def load(self, text: Any) -> Any:
        """Load one document; raise ruamel's YAMLError as rosbags expects."""
        from ruamel.yaml.error import YAMLError
        try:
            return yaml.load(text, Loader=self._LOADER)
        except yaml.YAMLError as e:
            raise YAMLError(" ".join(str(e).split())) from None

    def dump(self, data: Any, stream: Any) -> None:
        """Dump one document to ``stream``."""
        yaml.dump(data, stream, Dumper=self._DUMPER, default_flow_style=self.default_flow_style,
                  width=1 << 30)


@contextmanager
def fast_yaml() -> Iterator[None]:
    """Let rosbags' reader and writer use :class:`_LibYaml` for the duration."""
    import rosbags.rosbag2.metadata as m
    import rosbags.rosbag2.reader as r
    import rosbags.rosbag2.writer as w
    saved = [(mod, getattr(mod, "YAML")) for mod in (m, r, w)]
    for mod, _ in saved:
        setattr(mod, "YAML", _LibYaml)
    try:
        yield
    finally:
        for mod, original in saved:
            setattr(mod, "YAML", original)


# ------------------------------------------------------------------------ inputs

def input_name(path: Path | str) -> str:
    """Return the NAME of an input: the directory's name, or the file's without ``.mcap``."""
    if isinstance(path, str) and "://" in path:  # an fsspec URL
        base = path.rstrip("/").rsplit("/", 1)[-1]
        return base[:-len(".mcap")] if base.endswith(".mcap") and not path.endswith("/") \
            else base
    p = Path(os.path.abspath(path))
    return p.stem if p.suffix == ".mcap" and not p.is_dir() else p.name


def open_reader(source: Path) -> Reader:
    """Open a bag for reading; raise :class:`BadInput` naming it if it is not one."""
    if not os.path.lexists(source):
        raise BadInput(f"{source}: no such file or directory")
    if not source.is_dir() and source.suffix != ".mcap":
        raise BadInput(f"{source}: not a rosbag2 directory or an .mcap file")
    try:
        reader = Reader(source)
        reader.open()
    except Exception as e:
        raise BadInput(f"{source}: not a readable bag: {problem(e)}") from None
    return reader


def messages(reader: Reader, source: str) -> Iterator[tuple[Any, int, bytes]]:
    """Yield the reader's messages; turn any reading problem into :class:`BadInput`."""
    it = reader.messages()
    while True:
        try:
            item = next(it)
        except StopIteration:
            return
        except Exception as e:
            raise BadInput(f"{source}: unreadable: {problem(e)}") from None
        yield item


@functools.lru_cache(maxsize=256)
def standard_definition(msgtype: str) -> tuple[str, str]:
    """Return ``(msgdef, rihs01)`` of a ROS 2 Jazzy message type (computed once per type)."""
    text, _ = TYPESTORE.generate_msgdef(msgtype, ros_version=2)
    return text, TYPESTORE.hash_rihs01(msgtype)


def definition(conn: Any) -> tuple[str, str]:
    """Return ``(msgdef, rihs01)`` of an input connection, to copy it as it is."""
    msgdef, digest = conn.msgdef.data, conn.digest
    if msgdef and digest:
        return msgdef, digest
    if conn.msgtype in TYPESTORE.fielddefs:
        return standard_definition(conn.msgtype)
    try:  # a type of its own: hash the definition the bag carries
        store = get_typestore(Stores.EMPTY)
        store.register(get_types_from_msg(msgdef, conn.msgtype))
        return msgdef, store.hash_rihs01(conn.msgtype)
    except Exception as e:
        raise BadInput(f"topic {conn.topic}: no usable definition of type {conn.msgtype} "
                       f"({problem(e)})") from None


# ------------------------------------------------------------------------ outputs

def qos(reliability: str, depth: int) -> list[Qos]:
    """Return the offered QoS of the node's publishers: ``reliability``, keep last ``depth``."""
    rel = QosReliability.BEST_EFFORT if reliability == "best_effort" else QosReliability.RELIABLE
    return [Qos(QosHistory.KEEP_LAST, depth, rel, QosDurability.VOLATILE, QosTime(0, 0),
                QosTime(0, 0), QosLiveliness.AUTOMATIC, QosTime(0, 0), False)]


def open_writer(path: Path, custom_data: dict[str, str]) -> Writer:
    """Return a writer (not yet open) of a rosbag2 v9 MCAP bag with zstd chunk compression."""
    writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
    writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    for key, value in custom_data.items():
        writer.set_custom_data(key, value)
    return writer


def resolve(topic: str, namespace: str = "/") -> str:
    """Return the absolute name of ``topic`` in ``namespace``, as ROS resolves it.

    An absolute name stays; a relative one is put under the namespace (a
    bag's topic names resolve in the root namespace).
    """
    if topic.startswith("/"):
        return topic
    return f"{namespace.rstrip('/')}/{topic}"


def copy_connections(reader: Reader, writer: Writer, skip: set[str]) -> dict[int, Any]:
    """Add a copy of each input connection (topic, type, definition, QoS) but those in ``skip``.

    ``skip``: absolute topic names; a bag's relative names are resolved in
    the root namespace (:func:`resolve`) before they are compared.  Return
    ``{input connection id: output connection}``.
    """
    copies = {}
    for conn in reader.connections:
        if resolve(conn.topic) in skip:
            continue
        msgdef, digest = definition(conn)
        ext = conn.ext
        copies[conn.id] = writer.add_connection(
            conn.topic, conn.msgtype, msgdef=msgdef, rihs01=digest,
            serialization_format=getattr(ext, "serialization_format", "cdr"),
            offered_qos_profiles=getattr(ext, "offered_qos_profiles", ()))
    return copies
