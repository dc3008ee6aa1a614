"""Writes ball.msh: a solid ball of radius 0.25 m centred on the origin, meshed into tetrahedra by
Gmsh (edges about 5 cm), saved as Gmsh 4.1 ASCII. Needs `pip install gmsh`.

    python3 examples/scenes/assets/make_ball.py
"""

from pathlib import Path

import gmsh

gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("ball")
gmsh.model.occ.addSphere(0, 0, 0, 0.25)
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.05)
gmsh.option.setNumber("Mesh.MeshSizeMin", 0.03)
gmsh.option.setNumber("Mesh.RandomSeed", 1)
gmsh.model.mesh.generate(3)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.option.setNumber("Mesh.Binary", 0)
gmsh.write(str(Path(__file__).with_name("ball.msh")))
gmsh.finalize()
