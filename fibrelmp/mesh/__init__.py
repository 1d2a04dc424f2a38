"""Meshes of finite-element models (the CardioProof coupling): one neutral ``Mesh`` and a home
per mesh format, registered like every other format (registry role ``mesh``).

* ``opencarp/``  the openCARP ("Graz", CARP) format: ``.pts``/``.elem`` text, ``.bpts``/``.belem``
  binary, coordinates in µm; ``.dynpt`` node-position time series (IGB);
* ``vtkmesh/``   VTK unstructured grids (``.vtu``, ``.vtk``) through meshio.
"""
