// Validates glTF files with the Khronos glTF validator; prints one line per file
// ("FILE: N errors, N warnings, N infos, N hints") and every error and warning; exits 1 when
// any file has an error. Usage: node validate_gltf.mjs FILE.glb...
import validator from 'gltf-validator';
import fs from 'fs';

let failed = false;
for (const file of process.argv.slice(2)) {
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), { maxIssues: 200 });
  const i = report.issues;
  console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints`);
  for (const m of i.messages)
    if (m.severity <= 1) console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} at ${m.pointer}: ${m.message}`);
  if (i.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
