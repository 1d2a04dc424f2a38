"""CardioProof's reference sample for the conformance tests
(tests/conformance/test_cardioproof.py; docs/architecture.md, "Conformance tests")."""

CASE = "examples/cardioproof/piston_tube.json"      # a piston in a tube, its mesh and motion beside it
