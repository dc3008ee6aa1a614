"""Generates the skinned glTF test assets of anim-skin (run from this directory).

A cylinder along +y (radius 0.2, height 2, 12 segments, 17 rings, open ends) bound to a chain
of five joints under a non-joint "Armature" node; every vertex has five non-zero Gaussian
weights, so JOINTS_1/WEIGHTS_1 are needed. The mesh node carries a translation that glTF says
skinning must ignore. One animation uses all three interpolation modes on translation, rotation
and (non-uniform) scale channels. Three encodings of the same asset:

- skin_embedded.gltf: buffers as a base64 data URI; joints u8, weights f32.
- skin.glb: binary container; joints u16, weights normalised u8.
- skin_external.gltf + skin_external.bin: external buffer; joints u16, weights normalised u16.

    pip install pygltflib numpy && python make_assets.py
"""
import numpy as np
import pygltflib as g

SEG, RINGS, RADIUS, HEIGHT = 12, 17, 0.2, 2.0
JOINT_Y = np.array([0.0, 0.5, 1.0, 1.5, 2.0])


def quat_axis(axis, deg):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    h = np.radians(deg) / 2
    return np.concatenate([axis * np.sin(h), [np.cos(h)]])


def mesh():
    pos, nrm = [], []
    for r in range(RINGS):
        y = HEIGHT * r / (RINGS - 1)
        for s in range(SEG):
            a = 2 * np.pi * s / SEG
            pos.append([RADIUS * np.cos(a), y, RADIUS * np.sin(a)])
            nrm.append([np.cos(a), 0.0, np.sin(a)])
    idx = []
    for r in range(RINGS - 1):
        for s in range(SEG):
            a, b = r * SEG + s, r * SEG + (s + 1) % SEG
            c, d = a + SEG, b + SEG
            idx += [a, c, b, b, c, d]
    pos = np.array(pos, np.float32)
    w = np.exp(-((pos[:, 1:2] - JOINT_Y[None, :]) ** 2) / (2 * 0.3**2))
    w = w / w.sum(axis=1, keepdims=True)
    weights = np.zeros((len(pos), 8))
    weights[:, :5] = w
    joints = np.zeros((len(pos), 8), int)
    joints[:, :5] = np.arange(5)
    return pos, np.array(nrm, np.float32), np.array(idx, np.uint16), joints, weights


def build(joint_type, weight_type):
    pos, nrm, idx, joints, weights = mesh()
    blob = bytearray()
    views, accessors = [], []

    def add(arr, ctype, atype, normalized=False, target=None, minmax=False):
        arr = np.ascontiguousarray(arr)
        while len(blob) % 4:
            blob.append(0)
        off = len(blob)
        blob.extend(arr.tobytes())
        views.append(g.BufferView(buffer=0, byteOffset=off, byteLength=arr.nbytes, target=target))
        acc = g.Accessor(bufferView=len(views) - 1, componentType=ctype, count=len(arr), type=atype,
                         normalized=normalized or None)
        if minmax:
            acc.min = np.atleast_1d(arr.min(axis=0)).tolist()
            acc.max = np.atleast_1d(arr.max(axis=0)).tolist()
        accessors.append(acc)
        return len(accessors) - 1

    a_pos = add(pos, g.FLOAT, g.VEC3, minmax=True, target=g.ARRAY_BUFFER)
    a_nrm = add(nrm, g.FLOAT, g.VEC3, target=g.ARRAY_BUFFER)
    a_idx = add(idx, g.UNSIGNED_SHORT, g.SCALAR, target=g.ELEMENT_ARRAY_BUFFER)
    attrs = g.Attributes(POSITION=a_pos, NORMAL=a_nrm)
    jt = {"u8": (np.uint8, g.UNSIGNED_BYTE), "u16": (np.uint16, g.UNSIGNED_SHORT)}[joint_type]
    for s in range(2):
        j = joints[:, 4 * s:4 * s + 4].astype(jt[0])
        w = weights[:, 4 * s:4 * s + 4]
        if weight_type == "f32":
            aw = add(w.astype(np.float32), g.FLOAT, g.VEC4, target=g.ARRAY_BUFFER)
        elif weight_type == "u8n":
            aw = add(np.round(w * 255).astype(np.uint8), g.UNSIGNED_BYTE, g.VEC4, normalized=True, target=g.ARRAY_BUFFER)
        else:
            aw = add(np.round(w * 65535).astype(np.uint16), g.UNSIGNED_SHORT, g.VEC4, normalized=True, target=g.ARRAY_BUFFER)
        aj = add(j, jt[1], g.VEC4, target=g.ARRAY_BUFFER)
        setattr(attrs, f"JOINTS_{s}", aj)
        setattr(attrs, f"WEIGHTS_{s}", aw)

    # Nodes: 0 Armature, 1..5 joints (chain), 6 mesh.
    arm_t, arm_r, arm_s = [0.1, -0.2, 0.05], quat_axis([0, 0, 1], 10.0), [1.0, 1.0, 1.0]
    nodes = [g.Node(name="Armature", translation=arm_t, rotation=arm_r.tolist(), scale=arm_s, children=[1])]
    for i in range(5):
        nodes.append(g.Node(name=f"bone{i}", translation=[0.0, 0.0 if i == 0 else 0.5, 0.0],
                            children=[i + 2] if i < 4 else []))
    nodes.append(g.Node(name="Cylinder", mesh=0, skin=0, translation=[5.0, 0.0, 0.0]))

    # Inverse bind matrices: inverse of each joint's global bind transform.
    def trs(t, r, s):
        x, y, z, w = r
        R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                      [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                      [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
        M = np.eye(4)
        M[:3, :3] = R * np.asarray(s)[None, :]
        M[:3, 3] = t
        return M

    G = trs(arm_t, arm_r, arm_s)
    ibm = []
    for i in range(5):
        G = G @ trs([0, 0 if i == 0 else 0.5, 0], [0, 0, 0, 1], [1, 1, 1])
        ibm.append(np.linalg.inv(G).T.reshape(-1))  # column-major
    a_ibm = add(np.array(ibm, np.float32), g.FLOAT, g.MAT4)

    # Animation: every interpolation mode.
    samplers, channels = [], []

    def anim(node, path, times, values, interp):
        ai = add(np.array(times, np.float32), g.FLOAT, g.SCALAR, minmax=True)
        vals = np.array(values, np.float32)
        ao = add(vals, g.FLOAT, g.VEC4 if vals.shape[1] == 4 else g.VEC3)
        samplers.append(g.AnimationSampler(input=ai, output=ao, interpolation=interp))
        channels.append(g.AnimationChannel(sampler=len(samplers) - 1, target=g.AnimationChannelTarget(node=node, path=path)))

    anim(2, "rotation", [0.0, 1.0, 2.0], [quat_axis([0, 0, 1], 0), quat_axis([0, 0, 1], 60), quat_axis([1, 0, 1], -40)], g.ANIM_LINEAR)
    q = [quat_axis([1, 0, 0], 0), quat_axis([1, 0, 0], 45), quat_axis([1, 1, 0], -30)]
    tan = [[0.1, 0.0, 0.2, 0.0], [0.3, -0.1, 0.0, 0.05], [-0.2, 0.1, 0.1, 0.0]]
    cubic = []
    for k in range(3):
        cubic += [tan[k], q[k], [-c for c in tan[k]]]
    anim(3, "rotation", [0.0, 0.8, 2.0], cubic, g.ANIM_CUBICSPLINE)
    anim(4, "translation", [0.0, 1.0], [[0.0, 0.5, 0.0], [0.1, 0.6, 0.0]], g.ANIM_STEP)
    anim(5, "scale", [0.0, 2.0], [[1.0, 1.0, 1.0], [1.5, 0.8, 1.2]], g.ANIM_LINEAR)
    anim(0, "translation", [0.0, 1.0, 2.0],
         [[0, 0, 0], [0.1, -0.2, 0.05], [0.5, 0, 0],
          [0.2, 0.1, 0], [0.3, -0.1, 0.1], [0, 0, 0.4],
          [0, 0.3, 0], [0.0, -0.2, 0.2], [0, 0, 0]], g.ANIM_CUBICSPLINE)

    gl = g.GLTF2(
        scene=0,
        scenes=[g.Scene(nodes=[0, 6])],
        nodes=nodes,
        meshes=[g.Mesh(name="Cylinder", primitives=[g.Primitive(attributes=attrs, indices=a_idx)])],
        skins=[g.Skin(joints=[1, 2, 3, 4, 5], inverseBindMatrices=a_ibm, skeleton=1)],
        animations=[g.Animation(name="all-interpolations", samplers=samplers, channels=channels)],
        accessors=accessors,
        bufferViews=views,
        buffers=[g.Buffer(byteLength=len(blob))],
    )
    gl.set_binary_blob(bytes(blob))
    return gl


if __name__ == "__main__":
    a = build("u8", "f32")
    a.convert_buffers(g.BufferFormat.DATAURI)
    a.save("skin_embedded.gltf")
    b = build("u16", "u8n")
    b.save_binary("skin.glb")
    c = build("u16", "u16n")
    c.buffers[0].uri = "skin_external.bin"
    with open("skin_external.bin", "wb") as f:
        f.write(c.binary_blob())
    c._glb_data = None
    c.save_json("skin_external.gltf")
    print("wrote skin_embedded.gltf, skin.glb, skin_external.gltf + .bin")
