#!/bin/sh
# docs/log-format.md and docs/telemetry.md hold the field table as `craneassist fields` prints it.
#   docs_field_table.sh CRANEASSIST SOURCE_DIR
set -eu
table="$("$1" fields)"
for doc in "$2/docs/log-format.md" "$2/docs/telemetry.md"; do
  held="$(sed -n '/^<!-- the field table/,/^<!-- end of the field table/p' "$doc" | sed '1d;$d')"
  if [ "$held" != "$table" ]; then
    echo "$doc: its field table differs from craneassist fields (paste its output between the markers)"
    exit 1
  fi
done
echo "field table docs OK"
