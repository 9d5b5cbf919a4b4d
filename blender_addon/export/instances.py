# SPDX-License-Identifier: MIT
"""Many placements of one mesh as one node with EXT_mesh_gpu_instancing.

The depsgraph gives a node per instance (Geometry Nodes, collection instances, particles),
all sharing one glTF mesh. Past GPU_INSTANCING_MIN placements of a mesh, the nodes become
one node whose TRANSLATION / ROTATION / SCALE accessors hold each placement's T·R·S (and
_TESELA_RANDOM its Object Info random number); a placement with shear, which T·R·S cannot
express, keeps its own node."""

import numpy as np

from .buffer import FLOAT

GPU_INSTANCING_MIN = 64


def decompose(m):
    """Row-major 4x4 matrices (n, 4, 4) -> translations (n, 3), unit quaternions xyzw (n, 4),
    scales (n, 3) with m = T·R·S, and a mask of the matrices that are exactly that (no
    shear, invertible). A mirroring matrix gets a negative x scale."""
    t = m[:, :3, 3]
    lin = m[:, :3, :3]
    s = np.linalg.norm(lin, axis=1)  # column lengths
    det = np.linalg.det(lin)
    s[:, 0] *= np.where(det < 0.0, -1.0, 1.0)
    ok = np.all(np.abs(s) > 1e-12, axis=1) & np.isfinite(det)
    r = lin / np.where(np.abs(s) > 1e-12, s, 1.0)[:, None, :]
    ortho = np.einsum("nji,njk->nik", r, r)
    ok &= np.all(np.abs(ortho - np.eye(3)) < 1e-4, axis=(1, 2))
    # Shepperd's method, per matrix.
    q = np.zeros((m.shape[0], 4))
    tr = r[:, 0, 0] + r[:, 1, 1] + r[:, 2, 2]
    for i in range(m.shape[0]):
        a = r[i]
        if tr[i] > 0.0:
            w = np.sqrt(max(1.0 + tr[i], 0.0)) * 2.0
            q[i] = [(a[2, 1] - a[1, 2]) / w, (a[0, 2] - a[2, 0]) / w, (a[1, 0] - a[0, 1]) / w, 0.25 * w]
        elif a[0, 0] > a[1, 1] and a[0, 0] > a[2, 2]:
            w = np.sqrt(max(1.0 + a[0, 0] - a[1, 1] - a[2, 2], 1e-30)) * 2.0
            q[i] = [0.25 * w, (a[0, 1] + a[1, 0]) / w, (a[0, 2] + a[2, 0]) / w, (a[2, 1] - a[1, 2]) / w]
        elif a[1, 1] > a[2, 2]:
            w = np.sqrt(max(1.0 + a[1, 1] - a[0, 0] - a[2, 2], 1e-30)) * 2.0
            q[i] = [(a[0, 1] + a[1, 0]) / w, 0.25 * w, (a[1, 2] + a[2, 1]) / w, (a[0, 2] - a[2, 0]) / w]
        else:
            w = np.sqrt(max(1.0 + a[2, 2] - a[0, 0] - a[1, 1], 1e-30)) * 2.0
            q[i] = [(a[0, 2] + a[2, 0]) / w, (a[1, 2] + a[2, 1]) / w, 0.25 * w, (a[1, 0] - a[0, 1]) / w]
    q /= np.maximum(np.linalg.norm(q, axis=1), 1e-30)[:, None]
    return t, q, s, ok


def _collapsible(node):
    """Whether a node's object data is shared by every placement of its mesh (all but the
    random number and location, which the instancing node carries per instance); a moving
    placement keeps its own node, with its keys."""
    obj = node.get("extras", {}).get("tesela_object", {})
    extensions = node.get("extensions", {})
    return ("TESELA_light_linking" not in extensions and "TESELA_motion" not in extensions
            and "particle" not in obj and "instancer" not in obj.get("attributes", {}))


def collapse(doc, root_nodes, buf, mesh_nodes, used_ext, threshold=GPU_INSTANCING_MIN):
    """Replace the nodes of each mesh placed more than `threshold` times by one instancing
    node. `mesh_nodes`: glTF mesh index -> indices of the (root, childless) nodes placing it.
    Returns the number of nodes replaced."""
    drop = set()
    added = []
    for mi, idx in mesh_nodes.items():
        # A linked object keeps its own node: an instancing node carries one set of links;
        # likewise an instance with a Particle Info or Instancer attributes of its own.
        idx = [i for i in idx if _collapsible(doc["nodes"][i])]
        if len(idx) <= threshold:
            continue
        cols = np.array([doc["nodes"][i]["matrix"] for i in idx], dtype=np.float64)
        m = cols.reshape(-1, 4, 4).transpose(0, 2, 1)
        t, q, s, ok = decompose(m)
        keep = np.nonzero(ok)[0]
        if len(keep) <= threshold:
            continue
        nodes = [doc["nodes"][idx[k]] for k in keep]
        randoms = np.array([n.get("extras", {}).get("tesela_object", {}).get("random", 0.0)
                            for n in nodes], dtype=np.float32)
        attrs = {"TRANSLATION": buf.add(t[keep].astype(np.float32), FLOAT, "VEC3", None),
                 "ROTATION": buf.add(q[keep].astype(np.float32), FLOAT, "VEC4", None),
                 "SCALE": buf.add(s[keep].astype(np.float32), FLOAT, "VEC3", None),
                 "_TESELA_RANDOM": buf.add(randoms, FLOAT, "SCALAR", None)}
        extras = dict(nodes[0].get("extras", {}))
        if "tesela_object" in extras:
            # Each instance's location is its own origin (the loader takes it from T·R·S).
            obj = dict(extras["tesela_object"])
            obj.pop("location", None)
            obj.pop("random", None)
            extras["tesela_object"] = obj
        added.append({"name": nodes[0].get("name", "mesh") + " instances", "mesh": mi,
                      "extensions": {"EXT_mesh_gpu_instancing": {"attributes": attrs}},
                      "extras": extras})
        drop.update(idx[k] for k in keep)
    if not added:
        return 0
    doc["nodes"] = [n for i, n in enumerate(doc["nodes"]) if i not in drop] + added
    root_nodes[:] = list(range(len(doc["nodes"])))
    used_ext.add("EXT_mesh_gpu_instancing")
    return len(drop)
