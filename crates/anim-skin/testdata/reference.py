"""Independent reference poses for anim-skin's conformance test (run from this directory).

Reads each test asset with pygltflib and numpy only (its own accessor decoding, glTF 2.0
animation sampling, node hierarchy, skin matrices and linear blend skinning; nothing shared with
the Rust code) and writes the posed world-space vertex positions and unit normals at several
times to reference_poses.json.

    pip install pygltflib numpy && python reference.py
"""
import base64
import json
import os

import numpy as np
import pygltflib as g

FILES = ["skin_embedded.gltf", "skin.glb", "skin_external.gltf"]
TIMES = [-0.5, 0.3, 0.8, 1.0, 1.37, 2.5]
DTYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def buffers(path, gl):
    out = []
    for b in gl.buffers:
        if b.uri is None:
            out.append(gl.binary_blob())
        elif b.uri.startswith("data:"):
            out.append(base64.b64decode(b.uri.split(",", 1)[1]))
        else:
            with open(os.path.join(os.path.dirname(path), b.uri), "rb") as f:
                out.append(f.read())
    return out


def read(gl, bufs, i):
    a = gl.accessors[i]
    v = gl.bufferViews[a.bufferView]
    dt = np.dtype(DTYPES[a.componentType])
    n = NCOMP[a.type]
    stride = v.byteStride or dt.itemsize * n
    base = (v.byteOffset or 0) + (a.byteOffset or 0)
    raw = bufs[v.buffer]
    rows = [np.frombuffer(raw, dt, n, base + k * stride) for k in range(a.count)]
    x = np.array(rows, dtype=np.float64)
    if a.normalized:
        x = x / np.iinfo(dt).max
    return x


def qmat(q):
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def slerp(a, b, s):
    d = np.dot(a, b)
    if d < 0:
        b, d = -b, -d
    if d > 1 - 1e-12:
        r = a + s * (b - a)
        return r / np.linalg.norm(r)
    th = np.arccos(min(d, 1.0))
    return (np.sin((1 - s) * th) * a + np.sin(s * th) * b) / np.sin(th)


def sample(times, values, interp, is_rot, t):
    n = len(times)
    cubic = interp == "CUBICSPLINE"
    val = (lambda k: values[3 * k + 1]) if cubic else (lambda k: values[k])
    if t <= times[0]:
        return val(0)
    if t >= times[-1]:
        return val(n - 1)
    k = int(np.searchsorted(times, t, side="right")) - 1
    td = times[k + 1] - times[k]
    s = (t - times[k]) / td
    if interp == "STEP":
        return val(k)
    if interp == "LINEAR":
        return slerp(val(k), val(k + 1), s) if is_rot else (1 - s) * val(k) + s * val(k + 1)
    p0, m0 = values[3 * k + 1], td * values[3 * k + 2]
    p1, m1 = values[3 * k + 4], td * values[3 * k + 3]
    h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
    r = h00 * p0 + h10 * m0 + h01 * p1 + h11 * m1
    return r / np.linalg.norm(r) if is_rot else r


def pose(path):
    gl = g.GLTF2.load(path)
    bufs = buffers(path, gl)
    anim = gl.animations[0]
    chans = []
    for c in anim.channels:
        smp = anim.samplers[c.sampler]
        chans.append((c.target.node, c.target.path, read(gl, bufs, smp.input)[:, 0], read(gl, bufs, smp.output), smp.interpolation))
    parent = {}
    for i, nd in enumerate(gl.nodes):
        for c in nd.children or []:
            parent[c] = i
    skin = gl.skins[0]
    ibm = read(gl, bufs, skin.inverseBindMatrices).reshape(-1, 4, 4).transpose(0, 2, 1)
    mesh_node = next(nd for nd in gl.nodes if nd.skin is not None)
    prim = gl.meshes[mesh_node.mesh].primitives[0]
    pos = read(gl, bufs, prim.attributes.POSITION)
    nrm = read(gl, bufs, prim.attributes.NORMAL)
    joints = np.hstack([read(gl, bufs, prim.attributes.JOINTS_0), read(gl, bufs, prim.attributes.JOINTS_1)]).astype(int)
    weights = np.hstack([read(gl, bufs, prim.attributes.WEIGHTS_0), read(gl, bufs, prim.attributes.WEIGHTS_1)])
    weights = weights / weights.sum(axis=1, keepdims=True)
    out = []
    for t in TIMES:
        local = {}
        for i, nd in enumerate(gl.nodes):
            local[i] = [np.array(nd.translation or [0, 0, 0], float), np.array(nd.rotation or [0, 0, 0, 1], float),
                        np.array(nd.scale or [1, 1, 1], float)]
        for node, path_, times, vals, interp in chans:
            k = {"translation": 0, "rotation": 1, "scale": 2}[path_]
            local[node][k] = sample(times, vals, interp, path_ == "rotation", t)

        def world(i):
            T, R, S = local[i]
            M = np.eye(4)
            M[:3, :3] = qmat(R) @ np.diag(S)
            M[:3, 3] = T
            return world(parent[i]) @ M if i in parent else M

        J = np.array([world(j) @ ibm[k] for k, j in enumerate(skin.joints)])
        P, N = [], []
        for v in range(len(pos)):
            A = sum(weights[v, i] * J[joints[v, i]] for i in range(8) if weights[v, i] > 0)
            P.append((A @ np.append(pos[v], 1.0))[:3])
            n = np.linalg.inv(A[:3, :3]).T @ nrm[v]
            N.append(n / np.linalg.norm(n))
        out.append({"t": t, "positions": np.round(np.array(P), 12).tolist(), "normals": np.round(np.array(N), 12).tolist()})
    return out


if __name__ == "__main__":
    ref = {"times": TIMES, "method": "linear blend skinning, glTF 2.0 sampling, numpy float64",
           "files": {f: pose(f) for f in FILES}}
    with open("reference_poses.json", "w") as f:
        json.dump(ref, f)
    print("wrote reference_poses.json")
