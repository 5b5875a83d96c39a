import sys

try:
    from .cli import main
except KeyboardInterrupt:  # Ctrl-C while still importing: same one line as later
    print("hystkit: interrupted", file=sys.stderr)
    sys.exit(130)

sys.exit(main())
