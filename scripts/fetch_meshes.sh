#!/usr/bin/env bash
# Fetches the public meshes into data/ (git-ignored), nothing else: the
# OFF files of CGAL's demo data (Debian's libcgal-demo, downloaded and
# unpacked here, not installed), bunny00.off, armadillo.off,
# ChineseDragon-10kv.off and refined_elephant.off among them. Needs
# apt-get and dpkg-deb; as root where the package lists are not yet read.
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ ! -f data/bunny00.off ]]; then
  echo "fetch_meshes: fetching the public meshes from libcgal-demo"
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  (cd "$tmp" && apt-get download libcgal-demo >/dev/null 2>&1 ||
     { apt-get update -qq && apt-get download libcgal-demo >/dev/null; })
  dpkg-deb -x "$tmp"/libcgal-demo_*.deb "$tmp/x"
  mkdir -p data
  tar -xzf "$tmp/x/usr/share/doc/libcgal-dev/data.tar.gz" -C "$tmp" --wildcards 'data/meshes/*.off'
  mv "$tmp"/data/meshes/*.off data/
fi
for m in bunny00 armadillo refined_elephant ChineseDragon-10kv; do
  [[ -f data/$m.off ]] || { echo "fetch_meshes: data/$m.off is missing after the fetch" >&2; exit 1; }
done
