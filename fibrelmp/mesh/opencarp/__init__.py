"""openCARP's ("Graz", CARP) mesh files: ``.pts`` + ``.elem`` (text) or ``.bpts`` + ``.belem``
(binary), node coordinates in µm, 0-based node indices, an optional region tag per element;
``.dynpt`` files (IGB) hold node positions over time.  Layout from openCARP's documentation and
meshtool's ``io_utils.cpp`` (docs/cardioproof.md)."""
