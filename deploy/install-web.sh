#!/usr/bin/env bash
# Installs the browser UI's npm packages (web/node_modules) exactly as
# web/package-lock.json pins them: three, three-mesh-bvh, Vite, terser,
# playwright-core, and ESLint, TypeScript and openapi-typescript for
# `npm run check`. Idempotent: skipped while the lockfile is unchanged since the
# last install. Needs Node.js >= 18.19 (Debian 12's nodejs 18.20 will do; the
# lockfile's packages are held to it by web/tests/unit/toolchain.test.mjs) and the
# npm registry (no CDN at run time: the UI is bundled from these packages by the
# CMake build).
set -euo pipefail
cd "$(dirname "$0")/../web"
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "install-web: Node.js and npm are needed (Node.js >= 18.19; deploy/install-deps.sh installs Debian's)" >&2
  exit 1
fi
version=$(node -p 'process.versions.node')
if ! node -e 'const [a,b]=process.versions.node.split(".").map(Number); process.exit(a>18||(a===18&&b>=19)?0:1)'; then
  echo "install-web: Node.js $version is too old; the UI's build (Vite) needs 18.19 or newer" >&2
  exit 1
fi
stamp=node_modules/.bodyscan-lock.sha256
want=$(sha256sum package-lock.json | cut -d' ' -f1)
if [[ -f "$stamp" && "$(cat "$stamp")" == "$want" && -f node_modules/vite/package.json ]]; then
  echo "install-web: npm packages up to date"
  exit 0
fi
echo "install-web: npm ci (Node.js $version)"
npm ci --no-audit --no-fund --loglevel=error
echo "$want" >"$stamp"
