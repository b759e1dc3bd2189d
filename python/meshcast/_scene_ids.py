"""The ids a Scene gives: ints that remember which scene gave them.

A mesh or instance id is the int it counts as (0, 1, ... in the order added;
an instance's is what casts report in ``instance``), so it indexes tables and
compares with answers as any int does. It also carries ``scene``, the number
of the scene that gave it: another scene refuses it with ``ValueError``
rather than take it for one of its own. A pickled scene keeps its number, so
the ids it gave stay good with its copies. A plain int is taken as an index
into the scene it is given to.
"""


class SceneId(int):
    """An id a Scene gave: its index, and ``scene``, the scene's number."""

    def __new__(cls, index, scene):
        self = int.__new__(cls, index)
        self.scene = scene
        return self

    def __repr__(self):
        return f"{type(self).__name__}({int(self)}, scene={self.scene:#018x})"

    def __reduce__(self):
        return (type(self), (int(self), self.scene))


class MeshId(SceneId):
    """A mesh a Scene gave (Scene.add_mesh)."""


class InstanceId(SceneId):
    """An instance a Scene gave (Scene.add_instance)."""
