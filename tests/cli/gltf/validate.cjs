// node validate.cjs FILE.glb: validates a glTF binary with the Khronos glTF
// validator (npm gltf-validator). Prints the issue counts and every error
// and warning; exits 1 when there is an error (or the file cannot be read),
// 0 otherwise. Run with NODE_PATH pointing at the installed node_modules.
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

const file = process.argv[2];
if (!file) {
  console.error('usage: node validate.cjs FILE.glb');
  process.exit(2);
}
const bytes = new Uint8Array(fs.readFileSync(file));
validator
  .validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,
    // Everything must be inside the .glb.
    externalResourceFunction: (uri) => Promise.reject(new Error('external resource ' + uri)),
  })
  .then((report) => {
    const i = report.issues;
    console.log(`validator ${report.validatorVersion}: ${i.numErrors} errors, ${i.numWarnings} warnings, ` +
                `${i.numInfos} infos, ${i.numHints} hints`);
    for (const m of i.messages)
      if (m.severity <= 1)
        console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} at ${m.pointer || '-'}: ${m.message}`);
    process.exit(i.numErrors > 0 ? 1 : 0);
  })
  .catch((e) => {
    console.error('validator failed: ' + e);
    process.exit(1);
  });
