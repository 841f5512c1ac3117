#!/usr/bin/env bash
# Builds the browser viewer: the probe codec and the bus format compiled to WebAssembly with
# emscripten (zstd included, from Debian's own source package), and the page's JavaScript
# dependencies from web/package-lock.json. Output: build/web/ (served as static files: only the page,
# its code and licences), and beside it the npm package for three.js applications
# (build/web-package/, web/package/README.md); intermediate files go in build/web-work/.
#   scripts/build-web.sh [OUT]      (OUT defaults to build/web)
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
OUT=$(realpath -m "${1:-$ROOT/build/web}")
WORK="$OUT-work"
mkdir -p "$OUT" "$WORK"
rm -rf "$OUT/obj" "$OUT/zstd" "$OUT/apt"  # where older builds kept them, inside the served folder

command -v emcc >/dev/null || { echo "build-web: emcc not found (apt install emscripten)" >&2; exit 1; }
# Debian's emscripten runs its JavaScript tools with the node on PATH; Debian's acorn lives here.
export NODE_PATH=/usr/share/nodejs${NODE_PATH:+:$NODE_PATH}

# zstd's sources: Debian's source package of the libzstd the native build links, fetched with
# apt's own signature and hash checks into a private apt state (the machine's sources untouched).
ZSTD="$WORK/zstd"
if [ ! -f "$ZSTD/lib/zstd.h" ]; then
  echo "build-web: fetching Debian's zstd source package"
  APT="$WORK/apt"
  rm -rf "$APT" "$ZSTD"
  mkdir -p "$APT/sources" "$APT/lists/partial" "$APT/cache/archives/partial" "$APT/get"
  uri="http://deb.debian.org/debian"
  if [ -f /etc/apt/sources.list.d/debian.sources ]; then
    u=$(awk '/^URIs:/ && $2 !~ /security/ {print $2; exit}' /etc/apt/sources.list.d/debian.sources)
    [ -n "$u" ] && uri=$u
  fi
  cat > "$APT/sources/zstd.sources" <<SRC
Types: deb-src
URIs: $uri
Suites: bookworm
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
  opts=(-o "Dir::Etc::SourceList=/dev/null" -o "Dir::Etc::SourceParts=$APT/sources"
        -o "Dir::State::Lists=$APT/lists" -o "Dir::Cache=$APT/cache" -o "APT::Sandbox::User=root" -qq)
  apt-get "${opts[@]}" update
  (cd "$APT/get" && apt-get "${opts[@]}" source --download-only libzstd)
  mkdir -p "$ZSTD"
  tar -xf "$(ls "$APT"/get/libzstd_*.orig.tar.* | grep -v "\.asc$" | head -1)" -C "$ZSTD" --strip-components=1 --wildcards '*/lib/*' '*/LICENSE'
  rm -rf "$APT"
fi

# The codec's sources, as codec/CMakeLists.txt lists them (it is the one list).
mapfile -t CODEC < <(sed -n '/^add_library(probecast_codec/,/^)/p' "$ROOT/codec/CMakeLists.txt" | grep -o 'src/[a-z0-9_]*\.cpp' | sed "s|^|$ROOT/codec/|")
ZSRC=("$ZSTD"/lib/common/*.c "$ZSTD"/lib/compress/*.c "$ZSTD"/lib/decompress/*.c)

echo "build-web: emcc ($(emcc --version | head -1))"
OBJ="$WORK/obj"
mkdir -p "$OBJ"
objs=()
compile() {  # SOURCE FLAGS...
  local src=$1 obj
  shift
  obj="$OBJ/$(echo "$src" | sed "s|^$ROOT/||; s|^$WORK/||; s|/|_|g").o"
  if [ ! -f "$obj" ] || [ "$src" -nt "$obj" ]; then
    emcc -c "$src" -o "$obj" "$@"
  fi
  objs+=("$obj")
}
CXXFLAGS=(-std=c++20 -Oz -ffp-contract=off -fno-exceptions -DNDEBUG -I"$ROOT/codec/include" -I"$ROOT/service/bus/include" -I"$ZSTD/lib")
CFLAGS=(-Oz -DNDEBUG -DZSTD_DISABLE_ASM -DZSTD_MULTITHREAD=0 -DZSTD_LEGACY_SUPPORT=0 -I"$ZSTD/lib" -I"$ZSTD/lib/common")
for s in "${ZSRC[@]}"; do compile "$s" "${CFLAGS[@]}"; done
for s in "${CODEC[@]}" "$ROOT/service/bus/bus_format.cpp" "$ROOT/web/wasm/probecast_web.cpp"; do
  compile "$s" "${CXXFLAGS[@]/-fno-exceptions/-fexceptions}"
done
emcc "${objs[@]}" -Oz -fexceptions -o "$OUT/probecast_codec.mjs" \
  -sMODULARIZE=1 -sEXPORT_ES6=1 -sEXPORT_NAME=createProbecastCodec -sENVIRONMENT=web,node \
  -sALLOW_MEMORY_GROWTH=1 -sFILESYSTEM=0 \
  -sEXPORTED_RUNTIME_METHODS='["UTF8ToString"]' \
  -sEXPORTED_FUNCTIONS='["_malloc","_free"]'
echo "build-web: $OUT/probecast_codec.mjs $(stat -c %s "$OUT/probecast_codec.mjs") B + .wasm $(stat -c %s "$OUT/probecast_codec.wasm") B"

# The page and the JavaScript it imports (from web/package-lock.json).
if [ ! -d "$ROOT/web/node_modules/three" ] || [ "$ROOT/web/package-lock.json" -nt "$ROOT/web/node_modules/.package-lock.json" ]; then
  echo "build-web: npm ci (web/package-lock.json)"
  (cd "$ROOT/web" && npm ci --no-audit --no-fund --loglevel=error)
fi
# One minified ES module (esbuild) with three.js and nats.ws; iwer is a chunk of its own, loaded
# only with xr=emulate. The codec (probecast_codec.mjs/.wasm) stays beside it, loaded at run time.
rm -rf "$OUT/src" "$OUT/vendor" "$OUT"/viewer.js "$OUT"/chunk-*.js "$OUT"/iwer.module-*.js
NM="$ROOT/web/node_modules"
"$NM/.bin/esbuild" "$ROOT/web/src/viewer.js" --bundle --minify --format=esm --splitting --outdir="$OUT" \
  --external:crypto --alias:nats.ws="$NM/nats.ws/esm/nats.js" --alias:iwer="$NM/iwer/build/iwer.module.js" \
  --loader:.h=text --legal-comments=linked --log-level=warning
cp "$ROOT/web/index.html" "$OUT/"
mkdir -p "$OUT/licenses"
cp "$NM/three/LICENSE" "$OUT/licenses/three.LICENSE"
cp "$NM/nats.ws/LICENSE" "$OUT/licenses/nats.ws.LICENSE"
cp "$NM/iwer/LICENSE" "$OUT/licenses/iwer.LICENSE"
cp "$ZSTD/LICENSE" "$OUT/licenses/zstd.LICENSE"  # compiled into the codec's WebAssembly
echo "build-web: page in $OUT (index.html)"

# The npm package (web/package): the module for three.js applications, bundled without three and
# nats.ws (the application's own), the codec beside it; packed into $OUT-package/*.tgz.
PKG="$OUT-package/probecast-three"
rm -rf "$OUT-package" && mkdir -p "$PKG/dist/licenses" "$PKG/example"
"$NM/.bin/esbuild" "$ROOT/web/package/index.js" --bundle --format=esm --outfile="$PKG/dist/probecast-three.js" \
  --external:three --external:'three/*' --external:nats.ws --loader:.h=text --log-level=warning
cp "$OUT/probecast_codec.mjs" "$OUT/probecast_codec.wasm" "$PKG/dist/"
cp "$ZSTD/LICENSE" "$PKG/dist/licenses/zstd.LICENSE"
cp "$ROOT/web/package/package.json" "$ROOT/web/package/README.md" "$ROOT/LICENSE" "$PKG/"
cp "$ROOT/web/package/example/index.html" "$ROOT/web/package/example/example.js" "$PKG/example/"
(cd "$OUT-package" && npm pack ./probecast-three --silent >/dev/null)
echo "build-web: npm package $(ls "$OUT-package"/*.tgz)"
