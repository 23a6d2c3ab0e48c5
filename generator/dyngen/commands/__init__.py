"""One module per `dyngen` command, each thin over its step function; dyngen.cli only dispatches."""
