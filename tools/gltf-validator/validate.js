// Validates glTF/glb files with the Khronos glTF validator; prints one summary line per file and
// exits 1 when any file has an error. Usage: node validate.js FILE...
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

async function validate(file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(data)));
      }),
  });
  const issues = report.issues;
  console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos`);
  for (const m of issues.messages) if (m.severity === 0) console.log(`  error ${m.code} at ${m.pointer}: ${m.message}`);
  return issues.numErrors;
}

(async () => {
  let errors = 0;
  for (const f of process.argv.slice(2)) errors += await validate(f);
  process.exit(errors > 0 ? 1 : 0);
})().catch((e) => {
  console.error(`validate.js: ${e}`);
  process.exit(2);
});
