"""Writes torus.msh: a solid torus (major radius 0.3 m, minor radius 0.1 m, axis z) meshed into
tetrahedra by Gmsh, saved as Gmsh 4.1 ASCII. Needs `pip install gmsh`.

    python3 examples/scenes/assets/make_torus.py
"""

from pathlib import Path

import gmsh

gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("torus")
gmsh.model.occ.addTorus(0, 0, 0, 0.3, 0.1)
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.06)
gmsh.option.setNumber("Mesh.MeshSizeMin", 0.03)
gmsh.option.setNumber("Mesh.RandomSeed", 1)
gmsh.model.mesh.generate(3)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.option.setNumber("Mesh.Binary", 0)
gmsh.write(str(Path(__file__).with_name("torus.msh")))
gmsh.finalize()
