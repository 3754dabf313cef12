# bench/doc_section.sh — sourced by the benchmark scripts.
# replace_doc_section NAME BODY: replaces what lies between the lines
# <!-- NAME:begin --> and <!-- NAME:end --> of docs/performance.md with BODY.
replace_doc_section() {
  local name=$1 body=$2 doc=docs/performance.md tmp
  tmp=$(mktemp)
  awk -v body="$body" -v begin="<!-- $name:begin -->" -v end="<!-- $name:end -->" '
    $0 == begin { print; print body; skip = 1; next }
    $0 == end { skip = 0 }
    !skip { print }
  ' "$doc" >"$tmp"
  mv "$tmp" "$doc"
  echo "bench: updated the $name section of $doc" >&2
}
