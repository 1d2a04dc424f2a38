"""MUSEN's home: text scenes and results, cmusen job scripts (``.mdem`` files: ``mdem/``).

* ``text``, ``scene``  the one MUSEN text reader, and the neutral ``GranularModel`` of a scene;
* ``text_writer``, ``writer``  the one text writer's lines, and the run-result writer;
* ``script``, ``script_parse``, ``script_settings``  cmusen job scripts: parsing, settings;
* ``input``, ``script_input``  the input hooks of text scenes and of cmusen scripts (their
  run plans);
* ``target``     ``post --to musen``; ``pictures``: the ``plot``/``snapshot`` source;
* ``samples``    the reference samples of the conformance tests.
"""
