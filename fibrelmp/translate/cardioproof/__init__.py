"""The CardioProof coupling: a moving finite-element surface mesh as the wall of an SPH fluid
(Tait water) on LAMMPS, with pressure-outflow openings (docs/cardioproof.md).  The
format's home:

* ``input``     the input hook (``CaseInput``): check lines, where a run writes, its run plan;

* ``case``      the JSON case file (``{"cardioproof": 1, ...}``): the neutral ``SphCase``;
* ``geometry``  surface triangles, the fluid filling, wall particles and their motion;
* ``job``       the LAMMPS job (``in.lammps``, ``data.lammps``, the wall velocity files);
* ``results``   frames back from the dumps, VTK frames and the per-opening CSV series;
* ``samples``   the reference case of the conformance tests.

The meshes themselves are ``fibrelmp.mesh`` formats; the outflow law is
``fibrelmp.mesh.outflow`` (numpy), which the tests compare with what LAMMPS applies.
"""
