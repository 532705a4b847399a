// Writes src/api-types.d.ts, the TypeScript form of the server's OpenAPI document
// (server/api/openapi.json), made by openapi-typescript. src/api.js types its
// calls with it, so `npm run typecheck` fails when the client and the document
// disagree. With --check it writes nothing and fails, saying what to run, when the
// committed file is not what the document gives now.
import { readFileSync, writeFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import openapiTS, { astToString } from 'openapi-typescript';

const DOCUMENT = new URL('../../server/api/openapi.json', import.meta.url);
const OUTPUT = new URL('../src/api-types.d.ts', import.meta.url);
const HEADER = `// Made from server/api/openapi.json by openapi-typescript (npm run gen:api-types
// in web/): do not edit; change the document and run it again.\n\n`;

// An object the document leaves open (a rig camera's fields) is Record<string,
// unknown>: its fields are read through a type the page states, not assumed absent.
const generated = HEADER + astToString(await openapiTS(DOCUMENT, { emptyObjectsUnknown: true }));
const output = fileURLToPath(OUTPUT);

if (process.argv.includes('--check')) {
  let committed = null;
  try {
    committed = readFileSync(OUTPUT, 'utf8');
  } catch {
    // missing: reported below like a stale one
  }
  if (committed !== generated) {
    console.error(`${output} is not what server/api/openapi.json gives: run \`npm run gen:api-types\` in web/ and commit the result.`);
    process.exit(1);
  }
  console.log('api-types: src/api-types.d.ts matches server/api/openapi.json');
} else {
  writeFileSync(OUTPUT, generated);
  console.log(`api-types: wrote ${output}`);
}
