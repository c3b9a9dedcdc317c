#!/usr/bin/env bash
# Builds the book (docs/book, mdBook) into target/book and the library's API docs
# (cargo doc, warnings are errors) into target/doc; tools/test.sh runs it. mdBook is
# installed from crates.io at a pinned version into target/tools (about 2 CPU-minutes the
# first time; a machine that has it skips that). The book's links and TOML snippets are
# checked by tests/book_links.rs and tests/book_snippets.rs, its Python API page by
# python/tests/test_api_page.py.
set -euo pipefail
cd "$(dirname "$0")/.."
version=0.5.4
mdbook=target/tools/bin/mdbook
if [ "$("$mdbook" --version 2>/dev/null)" != "mdbook v$version" ]; then
  cargo install mdbook --version "$version" --locked --no-default-features --root target/tools --quiet
fi
"$mdbook" build docs/book --dest-dir "$PWD/target/book"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps -p blutrace --quiet
echo "tools/book.sh: the book is target/book/index.html, the library's API docs target/doc/blutrace/index.html"
