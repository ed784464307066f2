#!/usr/bin/env bash
# The documentation site in strict mode: a broken link, a page missing from the navigation
# or a missing file fails. Skipped (77) where MkDocs is not installed (setup.sh installs it).
#   mkdocs_build.sh SOURCE_DIR SITE_DIR
set -euo pipefail
if ! command -v mkdocs >/dev/null; then
  echo "mkdocs not installed: the site is not built (apt-get install mkdocs)"
  exit 77
fi
mkdocs build --strict --quiet -f "$1/mkdocs.yml" -d "$2"
echo "site built in $2: $(find "$2" -name '*.html' | wc -l) pages"
