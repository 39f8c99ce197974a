#!/usr/bin/env bash
# Fails when the product (README, docs, sources, tests, exercises, slides) speaks of its own
# development: session, issue or goal numbers, work periods, branches, source-file ids such as
# "seed003", or the times of runs. The product describes what it is and does; its history lives
# in git.
set -euo pipefail

cd "$(git -C "$(dirname "$0")" rev-parse --show-toplevel)"

# Case-insensitive extended regular expressions. A bare "issue" is fine, and so is another
# project's issue cited as owner/repo#N or project#N.
patterns=(
    '\bsessions? [0-9]+'
    '\b(this|that|last|next|each|every|a later|an earlier) session\b'
    "\bsession's\b"
    '\bissues? #?[0-9]+'
    '\bgoals? [0-9]+'
    "\bgoal [0-9]+'s\b"
    '\bwork periods?\b'
    '\bbranch(es)? `[^`]+`'
    '\b(on|in|from|the) (the )?branch [`"]?[a-z0-9_.-]+/?[a-z0-9_.-]*[`"]?'
    '\bh-(finalize|sirds|gpu|docs|perf|raster)\b'
    'seed ?0[0-9]{2}'
    '\b[0-9]{1,2}:[0-9]{2} UTC\b'
    '\b(UTC|run|measured|runs?) (on |\()?20[0-9]{2}-[0-9]{2}-[0-9]{2}\b'
    '\bbefore (this|the) change\b'
    '\b(in|of|since) (the )?(previous|last|earlier) sessions?\b'
)
regex=$(IFS='|'; printf '%s' "${patterns[*]}")

status=0
while IFS= read -r -d '' file; do
    [ -f "$file" ] || continue
    # Text files only.
    grep -Iq . "$file" 2>/dev/null || continue
    if hits=$(grep -InE -i -- "$regex" "$file"); then
        printf '%s\n' "$hits" | sed "s|^|$file:|"
        status=1
    fi
done < <(git ls-files -z -- README.md docs src crates tests exercises slides \
    ':!:slides/package-lock.json')

if [ "$status" -ne 0 ]; then
    echo "development history in the product (see the lines above): say what the code does and why" >&2
    exit 1
fi
echo "no development history in the product"
