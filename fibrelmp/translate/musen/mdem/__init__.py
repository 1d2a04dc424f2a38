"""MUSEN's binary ``.mdem`` files: read scenes and results, write results MUSEN opens.

Layers, bottom up (each module says more):

* ``container``  the block file (headers, two file threads, blocks of growing size);
* ``messages``   the protobuf messages, defined from their field numbers;
* ``document``   ``MdemFile`` (scene message + time points, read lazily) and ``MdemWriter``;
* ``blockindex`` the block descriptors as arrays, and which block holds time point i;
* ``timepoints`` time points <-> numpy arrays (a C fast path for large scenes);
* ``objects``    spheres, bonds and walls of a scene as arrays;
* ``text_export`` MUSEN text exactly as MUSEN's EXPORT_TO_TEXT writes it;
* ``text_import`` MUSEN text -> ``.mdem`` as MUSEN's IMPORT_FROM_TEXT makes it;
* ``model``      the neutral ``GranularModel`` of a ``.mdem`` scene, and ``MdemResultWriter``;
* ``input``      the input hook (``MdemSceneInput``, the text scene hook's subclass);
* ``target``     ``post --to mdem``; ``pictures``: the ``plot``/``snapshot`` source;
* ``samples``    the reference samples of the conformance tests.

A ``.mdem`` scene means what its text export means: ``read_scene`` hands MUSEN's own text form
of the scene to the text scene reader, so a scene reads the same from either form.
"""
