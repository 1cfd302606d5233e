# shellcheck shell=bash
# The system libraries speclight wants, found the way speclight finds them, and installed
# with apt-get only when missing. Sourced by scripts/setup.sh (and by tests/scripts):
#   missing_system_libs        # prints the Debian packages to install, one a line
#   install_system_libs        # installs them with apt-get as root, else a one-line notice
#
# libLLVM 16-19 (Mitsuba's LLVM backend): the search of speclight.render.variant.find_libllvm
# ($DRJIT_LIBLLVM_PATH, then libLLVM-N.so, libLLVM.so.N*, libLLVM-N.dylib and
# llvm-N/lib/libLLVM*.so* in its folders), and the linker cache (`ldconfig -p`). The cache
# lists Debian's libllvm19 by its SONAME libLLVM.so.19.1 only, not as libLLVM-19.so.
# libgfortran.so.5 (6S): the same folders and the linker cache.
# SPECLIGHT_LIB_DIRS (space-separated folders) replaces the folders searched.

_SPECLIGHT_LIB_DIRS_DEFAULT="/usr/lib/x86_64-linux-gnu /usr/lib64 /usr/lib /usr/local/lib \
/usr/lib/aarch64-linux-gnu /opt/homebrew/opt/llvm/lib /usr/local/opt/llvm/lib"

_linker_cache() {
    # The whole listing, then a match: `ldconfig -p | grep -q` under `set -o pipefail` fails
    # when grep stops reading before a long listing ends (SIGPIPE), which reads as "missing".
    ldconfig -p 2>/dev/null || true
}

# libLLVM 16-19 in a file name (libLLVM-19.so, libLLVM.so.19.1, llvm-19/lib/...) and in the
# linker cache's listing (libLLVM-17.so.1, libLLVM.so.19.1).
_LLVM_NAME='LLVM[-.](so[.])?1[6-9]([^0-9]|$)'
_LLVM_FOLDER='llvm-1[6-9]/'
_LLVM_CACHED='libLLVM(-1[6-9][.]so|[.]so[.]1[6-9])([^0-9]|$)'

_llvm_version_ok() {
    [[ $(basename "$1") =~ $_LLVM_NAME ]] || [[ $1 =~ $_LLVM_FOLDER ]]
}

have_libllvm() {
    if [[ -n "${DRJIT_LIBLLVM_PATH:-}" && -e "$DRJIT_LIBLLVM_PATH" ]] &&
        _llvm_version_ok "$DRJIT_LIBLLVM_PATH"; then
        return 0
    fi
    local dir version pattern hit
    for version in 19 18 17 16; do
        for dir in ${SPECLIGHT_LIB_DIRS:-$_SPECLIGHT_LIB_DIRS_DEFAULT}; do
            for pattern in "libLLVM-$version.so" "libLLVM.so.$version*" "libLLVM-$version.dylib" \
                "llvm-$version/lib/libLLVM*.so*"; do
                for hit in "$dir"/$pattern; do # the pattern unquoted: expanded in $dir
                    [[ -e $hit ]] && return 0
                done
            done
        done
    done
    local cache
    cache=$(_linker_cache)
    [[ $cache =~ $_LLVM_CACHED ]]
}

have_libgfortran5() {
    local dir hit
    for dir in ${SPECLIGHT_LIB_DIRS:-$_SPECLIGHT_LIB_DIRS_DEFAULT}; do
        for hit in "$dir"/libgfortran.so.5*; do
            [[ -e $hit ]] && return 0
        done
    done
    local cache
    cache=$(_linker_cache)
    [[ $cache == *libgfortran.so.5* ]]
}

missing_system_libs() {
    have_libllvm || echo libllvm19
    have_libgfortran5 || echo libgfortran5
}

install_system_libs() {
    local need
    mapfile -t need < <(missing_system_libs)
    ((${#need[@]})) || return 0
    local fallback="speclight falls back (scalar rendering, SPECTRL2 instead of 6S)"
    if [[ $(id -u) == 0 ]] && command -v apt-get >/dev/null; then
        echo "setup: installing ${need[*]} with apt-get" >&2
        { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need[@]}"; } \
            >/dev/null 2>&1 || echo "setup: notice: could not install ${need[*]}; $fallback" >&2
    else
        echo "setup: notice: ${need[*]} missing and apt-get not usable here; $fallback" >&2
    fi
}
