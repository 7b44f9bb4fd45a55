// Validates glb files with the Khronos glTF validator; prints one JSON summary line per file and exits 1 when
// any file has errors. Usage: node validate.mjs FILE.glb...
import { readFile } from 'node:fs/promises';
import validator from 'gltf-validator';

let failed = false;
for (const file of process.argv.slice(2)) {
  try {
    const data = new Uint8Array(await readFile(file));
    const report = await validator.validateBytes(data, { maxIssues: 100 });
    const { numErrors, numWarnings } = report.issues;
    const errors = report.issues.messages.filter((m) => m.severity === 0).map((m) => `${m.code} ${m.pointer ?? ''} ${m.message}`);
    console.log(JSON.stringify({ file, errors: numErrors, warnings: numWarnings, messages: errors.slice(0, 10) }));
    if (numErrors > 0) failed = true;
  } catch (e) {
    console.log(JSON.stringify({ file, errors: 1, messages: [String(e)] }));
    failed = true;
  }
}
process.exit(failed ? 1 : 0);
