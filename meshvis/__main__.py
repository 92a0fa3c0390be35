"""``python -m meshvis`` is the ``meshvis`` command."""

from meshvis.cli.main import program

if __name__ == "__main__":
    program()
