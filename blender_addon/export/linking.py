"""Blender's light and shadow linking as TESELA_light_linking (docs/extensions.md): link
collections numbered, each emitter naming its receiver and blocker collections, each object
its state in the collections it belongs to. The renderer turns the states into what each
emitter lights and which objects shadow it."""

from .. import compat


class LightLinking:
    """The link collections of the emitters among `objects` and every object's states in
    them."""

    def __init__(self, objects):
        self.ids = {}
        self.states = {}
        for obj in objects:
            for coll in compat.light_linking_collections(obj):
                if coll is None or coll.name in self.ids:
                    continue
                cid = self.ids[coll.name] = len(self.ids)
                for name, state in compat.light_linking_states(coll).items():
                    self.states.setdefault(name, []).append([cid, state])

    def extension(self, obj, instancer=None):
        """The node extension of `obj` (an instance's states are its instancer's when the
        instancer has any, as Cycles takes them), or None without linking."""
        if not self.ids:
            return None
        ext = {}
        receivers, blockers = compat.light_linking_collections(obj)
        if receivers is not None:
            ext["receivers"] = self.ids[receivers.name]
        if blockers is not None:
            ext["blockers"] = self.ids[blockers.name]
        links = self.states.get(instancer.name) if instancer is not None else None
        links = links or self.states.get(obj.name)
        if links:
            ext["links"] = links
        return ext or None
