"""pytest configuration: the tests exercise this checkout (pytest puts this folder on
``sys.path`` first), and the real test models are looked up in ``../shared/models/real``."""
