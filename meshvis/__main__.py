"""``python -m meshvis`` is the ``meshvis`` command."""

from meshvis.cli.main import main

if __name__ == "__main__":
    raise SystemExit(main())
