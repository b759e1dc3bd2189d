"""How Blobs, Scenes and RaycastingScenes travel between processes: pickling.

A Blob mapped from a file (``load(path, mmap=True)``) pickles as that file's
absolute path, its size and its checksum: a process that unpickles it maps
the file once, and every later Blob of the same file (the same path, size,
modification time and inode) is that one mapping again. A Blob in memory
pickles as its bytes. A Scene pickles as its blobs (each once, as above) and
its instance table; a RaycastingScene as its geometries' structures. The
counts of both kinds of arrival in this process are ``arrivals()``.
"""

import copyreg
import os
import socket
import threading

from . import _meshcast

_lock = threading.Lock()
_mapped = {}  # (path, size, mtime_ns, inode) -> the Blob mapping that file
_arrivals = {"mapped": 0, "bytes": 0}


def arrivals():
    """How many Blobs this process has made from pickles: ``mapped`` (files
    mapped, once each) and ``bytes`` (blobs unpickled from their bytes)."""
    with _lock:
        return dict(_arrivals)


def where():
    """This process, as an error names it: the Dask worker's address where it
    is one, and the machine's name."""
    try:
        from distributed import get_worker
        return f"worker {get_worker().address} on {socket.gethostname()}"
    except (ImportError, ValueError):
        return f"process {os.getpid()} on {socket.gethostname()}"


def reduce_blob(blob):
    if blob.mapped:
        return (blob_of_file, (blob.path, blob.nbytes, blob.checksum, blob.name))
    return (blob_of_bytes, (blob.to_bytes(), blob.name))


def blob_of_bytes(data, name):
    blob = _meshcast._from_bytes(data, name)
    with _lock:
        _arrivals["bytes"] += 1
    return blob


def blob_of_file(path, nbytes, checksum, name):
    """The Blob of the file at `path`, mapped once a process; ValueError or
    FileNotFoundError naming this process, the path and what differs from
    the file the Blob was pickled from."""
    with _lock:
        try:
            st = os.stat(path)
        except FileNotFoundError:
            raise FileNotFoundError(f"{where()}: the blob file {path} is missing (every worker must be able to read "
                                    "a mapped Blob's file at the same path)") from None
        key = (path, st.st_size, st.st_mtime_ns, st.st_ino)
        blob = _mapped.get(key)
        if blob is None:
            if st.st_size != nbytes:
                raise ValueError(f"{where()}: the blob file {path} has {st.st_size} bytes, "
                                 f"the file the Blob was pickled from {nbytes}")
            blob = _meshcast._load(path, True, name)
            # A file replaced under its path: the old mapping is left to the
            # Blobs that still hold it.
            for old in [k for k in _mapped if k[0] == path]:
                del _mapped[old]
            _mapped[key] = blob
            _arrivals["mapped"] += 1
    if blob.checksum != checksum:
        raise ValueError(f"{where()}: the blob file {path} has checksum {blob.checksum:#010x}, "
                         f"the file the Blob was pickled from {checksum:#010x} (the same size: other bytes)")
    return blob


def reduce_by_state(obj):
    # What pickle protocols 2 and later make of a Scene or a RaycastingScene
    # (its __getstate__, given to __setstate__ of an object made by
    # __new__), for every protocol: 0 and 1 would otherwise call the
    # extension type's base on the object (copyreg._reduce_ex), which
    # pybind11 answers by ending the process.
    return (copyreg.__newobj__, (type(obj),), obj.__getstate__())


def tokenize_blob(blob):
    # Dask's name for a Blob's content: two Blobs of the same bytes are one.
    return ("meshcast.Blob", blob.name, blob.nbytes, blob.checksum, blob.path)


def install():
    _meshcast.Blob.__reduce__ = reduce_blob
    _meshcast.Blob.__dask_tokenize__ = tokenize_blob
    _meshcast.Scene.__reduce__ = reduce_by_state
    _meshcast._RaycastingScene.__reduce__ = reduce_by_state
