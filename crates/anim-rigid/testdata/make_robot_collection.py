#!/usr/bin/env python3
"""Copies the URDF robot descriptions of `example-robot-data` into `robots/`, gzip-compressed.

    pip install example-robot-data==6.0.0
    python3 crates/anim-rigid/testdata/make_robot_collection.py

Every `*.urdf` under the package's `robots/` folder is written byte for byte (inside gzip, level
9, no file name or time stamp, so the output is reproducible) to
`robots/<package>/<path>.urdf.gz`, beside the package's own `README.md` (upstream and licence)
and `LICENSE` where it has one. Meshes are not copied: anim-rigid reads no `<visual>` or
`<collision>`.

Left out: packages whose licence forbids redistribution in derived collections
(`CC-BY-NC-ND-4.0`: `alex_description`). `robots/INDEX.md` lists every file with its package's
licence and says what was left out and why.
"""

import gzip
import os
import re
import shutil
import site
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "robots")
EXCLUDED_LICENCES = {"CC-BY-NC-ND-4.0"}


def find_collection():
    for base in site.getsitepackages() + [site.getusersitepackages()]:
        path = os.path.join(base, "cmeel.prefix", "share", "example-robot-data")
        if os.path.isdir(os.path.join(path, "robots")):
            return path
    sys.exit("example-robot-data not found: pip install example-robot-data==6.0.0")


def licence_of(readme):
    if not os.path.exists(readme):
        return "BSD-2-Clause (example-robot-data)"
    with open(readme, encoding="utf-8") as f:
        text = f.read()
    m = re.search(r"^licen[cs]e:\s*(.+)$", text, re.IGNORECASE | re.MULTILINE)
    return m.group(1).strip() if m else "BSD-2-Clause (example-robot-data)"


def main():
    src = os.path.join(find_collection(), "robots")
    if os.path.isdir(OUT):
        shutil.rmtree(OUT)
    os.makedirs(OUT)
    rows, left_out = [], []
    for package in sorted(os.listdir(src)):
        pdir = os.path.join(src, package)
        if not os.path.isdir(pdir):
            continue
        licence = licence_of(os.path.join(pdir, "README.md"))
        urdfs = []
        for root, _, files in os.walk(pdir):
            urdfs += [os.path.join(root, f) for f in files if f.endswith(".urdf")]
        if not urdfs:
            continue
        if licence in EXCLUDED_LICENCES:
            left_out += [(os.path.relpath(u, src), licence) for u in sorted(urdfs)]
            continue
        for extra in ("README.md", "LICENSE"):
            if os.path.exists(os.path.join(pdir, extra)):
                os.makedirs(os.path.join(OUT, package), exist_ok=True)
                shutil.copyfile(os.path.join(pdir, extra), os.path.join(OUT, package, extra))
        for urdf in sorted(urdfs):
            rel = os.path.relpath(urdf, src)
            dest = os.path.join(OUT, rel + ".gz")
            os.makedirs(os.path.dirname(dest), exist_ok=True)
            with open(urdf, "rb") as f:
                data = f.read()
            with open(dest, "wb") as raw:
                with gzip.GzipFile(filename="", mode="wb", compresslevel=9, fileobj=raw, mtime=0) as gz:
                    gz.write(data)
            rows.append((rel, licence, len(data)))
    with open(os.path.join(OUT, "INDEX.md"), "w", encoding="utf-8") as f:
        f.write("# Robot descriptions from example-robot-data 6.0.0\n\n")
        f.write(
            "Copied byte for byte (gzip-compressed) by `../make_robot_collection.py`. Each package's\n"
            "`README.md` names its upstream and licence; the collection's packaging is BSD-2-Clause\n"
            "(`../LICENSE-example-robot-data-BSD-2-Clause`).\n\n"
        )
        f.write("| file | licence | bytes |\n| --- | --- | --- |\n")
        for rel, licence, size in rows:
            f.write(f"| `{rel}` | {licence} | {size} |\n")
        if left_out:
            f.write("\nLeft out (their licence does not allow redistribution here):\n\n")
            for rel, licence in left_out:
                f.write(f"- `{rel}` ({licence})\n")
    print(f"{len(rows)} URDF files written to {OUT}, {len(left_out)} left out")


if __name__ == "__main__":
    main()
