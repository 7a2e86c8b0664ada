# Doxygen's input filter for README.md and docs/*.md (FILTER_PATTERNS in
# cmake/Doxyfile.in): the pages stay written for GitHub, this makes their
# links work in the API reference too. Doxygen 1.9.4 gives headings no
# GitHub-style ids, so links to a section (#live-display,
# docs/scenarios.md#limits) could not be resolved. Outside fenced code:
#   - every heading below the title gets an explicit id: GitHub's slug of its
#     text, prefixed by the page's name (the ids are global in Doxygen):
#     "## Live display" in README.md -> "## Live display {#readme-live-display}";
#   - links to a section follow: (#x) -> (#<page>-x), (docs/y.md#x) -> (#y-x);
#   - links to a tutorial open its example page: (tutorials/t.cpp) -> (@ref t.cpp);
#   - links to other files of the source tree, which are not in the
#     reference, become their text: [text](path) -> text.
# Usage (as Doxygen calls it): awk -f doxygen-markdown.awk FILE.md

function page_prefix(path, name) {
  name = path
  sub(/^.*\//, "", name)
  sub(/\.md$/, "", name)
  return tolower(name)
}

# GitHub's heading id: lower case, only letters, digits, spaces, '-' and '_'
# kept, each space a '-'; a repeated id gets -1, -2, ...
function slug(text, s) {
  s = tolower(text)
  gsub(/[^a-z0-9 _-]/, "", s)
  gsub(/ /, "-", s)
  if (s in seen) {
    seen[s]++
    s = s "-" seen[s]
  } else {
    seen[s] = 0
  }
  return s
}

function rewrite_target(target, file, anchor) {
  if (target ~ /^[a-z]+:/ || target ~ /^@ref /) return target
  if (target ~ /^#/) return "#" prefix "-" substr(target, 2)
  if (target ~ /\.md#/) {
    file = target
    sub(/#.*$/, "", file)
    anchor = target
    sub(/^[^#]*#/, "", anchor)
    return "#" page_prefix(file) "-" anchor
  }
  if (target ~ /\.md$/) return target
  if (target ~ /^tutorials\/[^\/]+\.cpp$/) return "@ref " substr(target, 11)
  return ""  # another file of the source tree: no link
}

# Rewrites every inline link [text](target) of a line.
function rewrite_links(line, out, text, target, new, open, link) {
  out = ""
  while (match(line, /\[[^\]]*\]\([^) ]*\)/)) {
    out = out substr(line, 1, RSTART - 1)
    link = substr(line, RSTART, RLENGTH)
    line = substr(line, RSTART + RLENGTH)
    open = index(link, "](")
    text = substr(link, 2, open - 2)
    target = substr(link, open + 2, length(link) - open - 2)
    new = rewrite_target(target)
    out = out (new == "" ? text : "[" text "](" new ")")
  }
  return out line
}

FNR == 1 { prefix = page_prefix(FILENAME); fence = "" }

# Fenced code is copied as it is.
/^[ \t]*(```|~~~)/ {
  marker = $0
  sub(/^[ \t]*/, "", marker)
  marker = substr(marker, 1, 3)
  if (fence == "") fence = marker
  else if (fence == marker) fence = ""
  print
  next
}
fence != "" { print; next }

/^##+[ \t]/ && !/\{#[^}]*\}[ \t]*$/ {
  text = $0
  sub(/^#+[ \t]+/, "", text)
  sub(/[ \t]+$/, "", text)
  print rewrite_links($0) " {#" prefix "-" slug(text) "}"
  next
}

{ print rewrite_links($0) }
