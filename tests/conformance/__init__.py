"""Conformance tests by inheritance: ``base.py`` holds one base class per registry role with
the checks every format of that role must pass; each ``test_<format>.py`` subclasses the base
classes of its format's roles with its reference samples.  ``test_registry.py`` fails when a
registered format/role has no subclass."""
