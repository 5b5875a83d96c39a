import sys

try:
    from .cli import program
except KeyboardInterrupt:  # Ctrl-C while still importing: same one line as later
    print("hystkit: interrupted", file=sys.stderr)
    sys.exit(130)

program()
