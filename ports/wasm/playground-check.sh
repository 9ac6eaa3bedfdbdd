#!/bin/sh
# ports/wasm/playground-check.sh — make playground-check: build the playground
# (ports/wasm/playground.sh) and test it in headless Chromium (ports/wasm/playground-check.mjs).
# Installs what is missing: Debian's chromium, nodejs and npm through apt-get (as root or through
# sudo; PRAY_NO_INSTALL=1 skips that), and puppeteer-core from npm into ports/build/npm (never
# into the source tree). CHROMIUM names another browser binary.
cd "$(dirname "$0")/../.." || exit 2
set -e
if [ -z "${PRAY_NO_INSTALL:-}" ] && command -v apt-get >/dev/null 2>&1; then
    missing=""
    for p in chromium nodejs npm; do
        case $p in nodejs) command -v node >/dev/null 2>&1 && continue ;; npm) command -v npm >/dev/null 2>&1 && continue ;; esac
        dpkg-query -W -f='${Status}\n' "$p" 2>/dev/null | grep -q 'ok installed' || missing="$missing $p"
    done
    if [ -n "$missing" ]; then
        if [ "$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi
        echo "installing:$missing"
        $SUDO apt-get update -qq
        # shellcheck disable=SC2086
        DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing >/dev/null
    fi
fi
sh ports/wasm/playground.sh
NPM=ports/build/npm
if [ ! -f $NPM/node_modules/puppeteer-core/package.json ]; then
    mkdir -p $NPM
    echo "npm: installing puppeteer-core into $NPM"
    # (PUPPETEER_SKIP_DOWNLOAD: the system's Chromium is used, no browser is downloaded)
    PUPPETEER_SKIP_DOWNLOAD=1 npm install --prefix $NPM --no-audit --no-fund --silent puppeteer-core@24
fi
node ports/wasm/playground-check.mjs
