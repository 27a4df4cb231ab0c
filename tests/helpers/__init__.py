"""What the tests share and are not tests themselves: readers of NC programs written
independently of the engine, reference models, drawings and data the tests build, the database
pool of the fixtures. Imported as `helpers.<module>` (pyproject.toml puts tests/ on pytest's
pythonpath); a test module never imports another test module (tests/test_test_layout.py)."""
