#!/usr/bin/env bash
# The fuzz targets' kept corpora (docs/fuzzing.md) are committed packed, one tests/fuzz/corpus/<target>.tar.xz per
# target (xz -9e finds the inputs' shared bytes across files: 48 MB of inputs pack into about 1 MB). The tests
# replay the archives as they are (tests/it/fuzz_corpus.rs); a fuzzing campaign needs them as folders:
#   scripts/fuzz-corpus.sh unpack [TARGET ...]   tests/fuzz/corpus/<target>.tar.xz -> tests/fuzz/corpus/<target>/
#   scripts/fuzz-corpus.sh pack [TARGET ...]     tests/fuzz/corpus/<target>/ -> tests/fuzz/corpus/<target>.tar.xz
# Without a TARGET, every target that has an archive (unpack) or a folder (pack). Packing is deterministic: names
# sorted, times, owners and modes fixed, so the same folder gives the same bytes.
set -euo pipefail
cd "$(dirname "$0")/../tests/fuzz/corpus"

usage() { echo "usage: scripts/fuzz-corpus.sh pack|unpack [TARGET ...]" >&2; exit 2; }
[ $# -ge 1 ] || usage
action=$1
shift

case "$action" in
  unpack)
    if [ $# -eq 0 ]; then mapfile -t targets < <(find . -maxdepth 1 -name '*.tar.xz' -printf '%f\n' | sed 's/\.tar\.xz$//' | sort); set -- "${targets[@]}"; fi
    for t in "$@"; do
      [ -f "$t.tar.xz" ] || { echo "fuzz-corpus: no archive tests/fuzz/corpus/$t.tar.xz" >&2; exit 1; }
      tar -xJf "$t.tar.xz"
      echo "tests/fuzz/corpus/$t/: $(find "$t" -type f | wc -l) inputs"
    done
    ;;
  pack)
    if [ $# -eq 0 ]; then mapfile -t targets < <(find . -mindepth 1 -maxdepth 1 -type d -printf '%f\n' | sort); set -- "${targets[@]}"; fi
    for t in "$@"; do
      [ -d "$t" ] || { echo "fuzz-corpus: no folder tests/fuzz/corpus/$t/ (unpack it, or run the fuzzer into it)" >&2; exit 1; }
      tar --sort=name --mtime=@0 --owner=0 --group=0 --numeric-owner --mode=a+rX,u+w,go-w --format=gnu \
        -cf - "$t" | xz -9e -T1 > "$t.tar.xz.partial"
      mv "$t.tar.xz.partial" "$t.tar.xz"
      echo "tests/fuzz/corpus/$t.tar.xz: $(find "$t" -type f | wc -l) inputs, $(stat -c %s "$t.tar.xz") bytes"
    done
    ;;
  *) usage ;;
esac
