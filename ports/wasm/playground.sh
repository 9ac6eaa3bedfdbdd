#!/bin/sh
# ports/wasm/playground.sh — build the playground into ports/build/playground/ (make playground):
# libpray.wasm (ports/wasm/wasm.mk), the page, and the examples with their textures (made by
# ./pray: make textures). Serve that directory with any static file server, e.g.
#     python3 -m http.server -d ports/build/playground 8000     ->  http://localhost:8000/
# Installs clang, lld and wasi-libc through apt-get when they are missing (Debian; as root or
# through sudo; PRAY_NO_INSTALL=1 skips that).
cd "$(dirname "$0")/../.." || exit 2
set -e
SITE=ports/build/playground

# need PACKAGE...: install those that are missing
need() {
    missing=""
    for p in "$@"; do
        dpkg-query -W -f='${Status}\n' "$p" 2>/dev/null | grep -q 'ok installed' || missing="$missing $p"
    done
    if [ -z "$missing" ] || [ -n "${PRAY_NO_INSTALL:-}" ] || ! command -v apt-get >/dev/null 2>&1; then
        return 0
    fi
    if [ "$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi
    echo "installing:$missing"
    $SUDO apt-get update -qq
    # shellcheck disable=SC2086
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing >/dev/null
}
need clang lld wasi-libc libclang-rt-14-dev-wasm32
make -s -f ports/wasm/wasm.mk ports/build/wasm/libpray.wasm
[ -f examples/tex/wood.tif ] || make -s textures

rm -rf $SITE
mkdir -p $SITE/examples/tex $SITE/examples/parts
cp ports/wasm/playground/index.html ports/wasm/playground/playground.js ports/wasm/playground/worker.js \
    ports/build/wasm/libpray.wasm $SITE/
# every example; the program files they include (examples/parts/) are lent to every program
examples=""
for f in examples/*.ray; do
    cp "$f" $SITE/examples/
    examples="$examples${examples:+, }\"$(basename "$f")\""
done
includes=""
for f in examples/parts/*.ray; do
    cp "$f" $SITE/examples/parts/
    includes="$includes${includes:+, }\"parts/$(basename "$f")\""
done
textures=""
for f in examples/tex/*.tif; do
    cp "$f" $SITE/examples/tex/
    textures="$textures${textures:+, }\"tex/$(basename "$f")\""
done
printf '{"examples": [%s],\n "textures": [%s],\n "includes": [%s]}\n' "$examples" "$textures" "$includes" >$SITE/examples/index.json
echo "playground: $SITE ($(wc -c <$SITE/libpray.wasm | tr -d ' ') bytes of libpray.wasm)"
