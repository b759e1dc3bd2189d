# Sourced: ninja_dir DIR installs Ninja and readies DIR for it, clearing a
# cache a Makefile configure left there (CMake refuses to switch generators
# in place). The builds that name several targets use Ninja: CMake's
# Makefiles build named targets one after another (their top level is
# .NOTPARALLEL), each test's own files then compile on one core while the
# other waits; Ninja builds them side by side.
source "$(dirname "${BASH_SOURCE[0]}")/packages.sh"
ninja_dir() {
  install_missing ninja-build
  if [[ -f $1/CMakeCache.txt ]] && ! grep -q '^CMAKE_GENERATOR:INTERNAL=Ninja$' "$1/CMakeCache.txt"; then
    rm -rf "$1/CMakeCache.txt" "$1/CMakeFiles"
  fi
}
