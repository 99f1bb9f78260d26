"""Reference solutions shared by unit and validation tests."""
