from .app.cli import EXIT_INTERRUPTED, main

try:
    status = main()
except KeyboardInterrupt:  # a Ctrl-C that lands while main() reports the first one: still 130, not a traceback
    status = EXIT_INTERRUPTED  # (nor a death by SIGINT, which CPython chooses for a KeyboardInterrupt left uncaught)
raise SystemExit(status)
