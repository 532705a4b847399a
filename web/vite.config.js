// Builds the browser UI. CMake runs it with --outDir BUILD/web, the folder
// `bodyscan serve` serves by default; `npm run build` alone writes web/dist.
// Hashed bundles go to assets/ (the server marks them immutable), the Draco
// decoder of the `three` package among them (DRACOLoader finds it by
// import.meta.url). Every text and wasm file also gets a .gz twin, which the
// server sends to browsers that take gzip: made by Zopfli, whose deflate streams
// any gzip reader takes and come out 4 % smaller than zlib's best.
import { defineConfig } from 'vite';
import { readdirSync, readFileSync, statSync, writeFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { gzipAsync } from '@gfx/zopfli';

/** @returns {import('vite').Plugin} */
function gzipTwins() {
  const compressible = /\.(js|mjs|css|html|svg|json|wasm|txt)$/;
  const walk = (dir) =>
    readdirSync(dir).flatMap((n) => {
      const p = join(dir, n);
      return statSync(p).isDirectory() ? walk(p) : [p];
    });
  let outDir = null;
  return {
    name: 'bodyscan-gzip-twins',
    apply: 'build',
    configResolved(config) {
      outDir = resolve(config.root, config.build.outDir);
    },
    closeBundle: {
      order: 'post',
      sequential: true,
      async handler() {
        for (const file of walk(outDir)) {
          if (!compressible.test(file)) continue;
          const raw = readFileSync(file);
          if (raw.length < 1024) continue;
          const gz = Buffer.from(await gzipAsync(raw, { numiterations: 15 }));
          if (gz.length < raw.length * 0.9) writeFileSync(`${file}.gz`, gz);
        }
      },
    },
  };
}

export default defineConfig({
  root: dirname(fileURLToPath(import.meta.url)),
  base: '/',
  plugins: [gzipTwins()],
  build: {
    outDir: 'dist',
    emptyOutDir: true,
    target: 'es2022',
    minify: 'terser',
    terserOptions: { module: true, ecma: 2020, compress: { passes: 2 } },
    sourcemap: true,
    chunkSizeWarningLimit: 1200,
  },
  server: {
    // `npm run dev` next to `bodyscan serve --port 8080`.
    proxy: { '/api': { target: 'http://localhost:8080', ws: true } },
  },
});
