"""Python client tests (a package so `unittest discover -t .` can import them)."""
