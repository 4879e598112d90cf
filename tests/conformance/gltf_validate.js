// SPDX-License-Identifier: Apache-2.0
// Validates .glb files with the Khronos glTF-Validator (npm's gltf-validator, found
// through NODE_PATH): one JSON line per file with its error and warning counts and its
// first errors.
const fs = require('fs');
const validator = require('gltf-validator');

(async () => {
    for (const file of process.argv.slice(2)) {
        const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {maxIssues: 20});
        const errors = report.issues.messages.filter(m => m.severity === 0)
                           .slice(0, 3).map(m => `${m.code} ${m.pointer || ''}: ${m.message}`);
        console.log(JSON.stringify({file, errors: report.issues.numErrors,
                                    warnings: report.issues.numWarnings, first: errors}));
    }
})().catch(e => { console.error(String(e)); process.exit(2); });
