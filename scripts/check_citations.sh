#!/usr/bin/env bash
# Fails when a source or doc file cites documentation that is not in the repository: a
# `docs/<file>.md` that does not exist, a section `docs/<file>.md §N` (or a labelled item such as
# `docs/math.md §2 R1`) without a heading in that file, a quoted heading (`docs/solver.md "Two
# paths"`) that no heading of the file contains, a bare `§N` inside a docs page that has no such
# heading of its own, or one of the design notes kept outside the repository (MATH.md,
# DESIGN.md, STYLE.md, SOLVER_ANCHORS.md, ../shared/), which a reader of the repository or of the
# installed headers never sees. Prints file:line and the missing target for each.
#   scripts/check_citations.sh [ROOT]   (default: the repository root)
# A section is a Markdown heading that starts with the section sign: "## §5 ...", "### §5.4 ...".
# A label (R1, A3, B4, ...) after §N must appear in a heading numbered N or N.x of the cited file.
# Only the pages that explain where their numbering comes from (docs/math.md,
# docs/architecture.md) and this script may name the outside notes.
set -euo pipefail
root="$(cd "${1:-$(dirname "${BASH_SOURCE[0]}")/..}" && pwd)"
cd "${root}"
export LC_ALL=C  # byte-wise matching: '§' is the two bytes C2 A7 in every file

# A citation: the file, then optionally sections (ranges and lists allowed) or a quoted heading.
section='§[0-9]+(?:\.[0-9]+)*(?: [RAB][0-9]+(?:-[RAB][0-9]+)?)?'
cite="(?<![A-Za-z0-9_./-])docs/(?:[A-Za-z0-9_-]+/)*[A-Za-z0-9_-]+\.md\`?"
cite+="(?: *(?:\"[^\"]+\"|${section}(?: *(?:[-,/]|and|or) *${section})*))?"
# The design notes outside the repository.
outside='\b(?:MATH|DESIGN|STYLE|SOLVER_ANCHORS)\.md\b|\bSOLVER_ANCHORS\b|\bMATH (?:§|[RAB][0-9])|\.\./shared/'
provenance=(docs/math.md docs/architecture.md scripts/check_citations.sh)

files=()
while IFS= read -r -d '' f; do files+=("${f#./}"); done < <(
  find . \( -path ./build -o -path ./out -o -path ./.git -o -path ./data -o -path ./tests/data \) \
    -prune -o -type f \( -name '*.h' -o -name '*.cc' -o -name '*.cpp' -o -name '*.txt' \
    -o -name '*.sh' -o -name '*.md' -o -name '*.cmake' -o -name '*.in' -o -name '*.py' \
    -o -name '.clang-format' -o -path './.ci/*' \) -print0 | sort -z)
if ((${#files[@]} == 0)); then
  echo "error: no source or doc files found under ${root}" >&2
  exit 2
fi

# Section headings of every docs page: "file|id" -> heading text.
declare -A headings=()
while IFS= read -r -d '' page; do
  page="${page#./}"
  while IFS= read -r heading; do
    id="$(grep -oP '^#+ §\K[0-9]+(?:\.[0-9]+)*' <<<"${heading}")"
    headings["${page}|${id}"]="${heading}"
  done < <(grep -P '^#{1,6} §[0-9]' "${page}" || true)
done < <(find docs -type f -name '*.md' -print0)

failures=0
# Reports one missing target: "file:line: <message>".
fail() {
  echo "$1: $2" >&2
  failures=$((failures + 1))
}

# True when `page` has a heading numbered `id`, or, with a label, numbered id or id.x and
# naming the label.
has_section() {
  local page="$1" id="$2" label="${3:-}" key
  if [[ -z "${label}" ]]; then
    [[ -n "${headings["${page}|${id}"]+x}" ]]
    return
  fi
  for key in "${!headings[@]}"; do
    [[ "${key%%|*}" == "${page}" ]] || continue
    local hid="${key#*|}"
    [[ "${hid}" == "${id}" || "${hid}" == "${id}."* ]] || continue
    if grep -qwF -- "${label}" <<<"${headings[${key}]}"; then return 0; fi
  done
  return 1
}

# Checks every "§N [label[-label]]" in `text` against `page`; `where` is file:line.
check_sections() {
  local where="$1" page="$2" text="$3" ref id labels label
  while IFS= read -r ref; do
    [[ -n "${ref}" ]] || continue
    id="$(grep -oP '^§\K[0-9]+(?:\.[0-9]+)*' <<<"${ref}")"
    labels="$(grep -oP ' \K[RAB][0-9]+(?:-[RAB][0-9]+)?$' <<<"${ref}" || true)"
    if [[ -z "${labels}" ]]; then
      has_section "${page}" "${id}" || fail "${where}" "cites ${page} §${id}, which has no heading §${id}"
      continue
    fi
    for label in ${labels//-/ }; do
      has_section "${page}" "${id}" "${label}" ||
        fail "${where}" "cites ${page} §${id} ${label}, but no heading §${id}[.x] of ${page} names ${label}"
    done
  done < <(grep -oP "${section}" <<<"${text}" || true)
}

echo "==> Citations of docs/ in ${#files[@]} source and doc files"
while IFS= read -r hit; do
  where="${hit%%:*}:$(cut -d: -f2 <<<"${hit}")"
  text="${hit#*:*:}"
  page="$(grep -oP '^docs/\S+?\.md' <<<"${text}")"
  if [[ ! -f "${page}" ]]; then
    fail "${where}" "cites ${page}, which does not exist"
    continue
  fi
  quoted="$(grep -oP '"\K[^"]+(?="$)' <<<"${text}" || true)"
  if [[ -n "${quoted}" ]]; then
    grep -P '^#{1,6} ' "${page}" | grep -qiF -- "${quoted}" ||
      fail "${where}" "cites ${page} \"${quoted}\", but no heading of ${page} contains it"
    continue
  fi
  check_sections "${where}" "${page}" "${text#"${page}"}"
done < <(grep -noP "${cite}" "${files[@]}" || true)

# Bare §N inside a docs page with numbered sections refers to the page itself (citations of
# other pages and of the papers' own sections are removed first).
mapfile -t numbered_pages < <(for key in "${!headings[@]}"; do echo "${key%%|*}"; done | sort -u)
for page in "${numbered_pages[@]}"; do
  while IFS= read -r hit; do
    text="${hit#*:}"
    while IFS= read -r cited; do
      [[ -n "${cited}" ]] && text="${text//"${cited}"/}"
    done < <(grep -oP "${cite}" <<<"${text}" || true)
    text="$(sed -E 's/[Pp]aper [AB] §[0-9.]+//g' <<<"${text}")"
    check_sections "${page}:${hit%%:*}" "${page}" "${text}"
  done < <(grep -nP '^(?!#).*§[0-9]' "${page}" || true)
done

echo "==> Notes kept outside the repository (MATH.md, DESIGN.md, STYLE.md, SOLVER_ANCHORS.md)"
while IFS= read -r hit; do
  file="${hit%%:*}"
  skip=0
  for allowed in "${provenance[@]}"; do [[ "${file}" == "${allowed}" ]] && skip=1; done
  ((skip)) && continue
  fail "${file}:$(cut -d: -f2 <<<"${hit}")" \
    "cites $(grep -oP "(?:${outside})[0-9.]*" <<<"${hit#*:*:}" | head -n1), which is not in the repository (cite docs/math.md or docs/architecture.md)"
done < <(grep -nP "${outside}" "${files[@]}" || true)

# A citation split after its file name (the file at the end of one line, its §N or quoted heading
# at the start of the next) is not checked above: keep each citation on one line.
while IFS= read -r hit; do
  fail "${hit%: *}" "${hit##*: }"
done < <(awk 'FNR == 1 { split_at = 0 }
  split_at && /^[ \t]*(\/\/|#|\*)?[ \t]*(§|")/ { print FILENAME ":" FNR - 1 ": citation split across lines" }
  { split_at = /docs\/[A-Za-z0-9_\/-]+\.md`?[ \t]*$/ }' "${files[@]}")

if ((failures > 0)); then
  echo "==> check_citations.sh FAILED: ${failures} citation(s) without a target" >&2
  exit 1
fi
echo "==> Every citation points at a file and section that exist"
