// SPDX-License-Identifier: MIT
// Runs the Khronos glTF validator (tools/node_modules, `npm ci` in tools/) on one file.
// Prints the issue counts and every error/warning; exits 0 when there are no errors, 1 when there are,
// 77 (the tests' "skipped") when the validator package is not installed.
'use strict';
const fs = require('fs');
const path = require('path');

let validator;
try {
    validator = require('gltf-validator');
} catch (error) {
    console.error('validate_gltf: gltf-validator is not installed (run `npm ci` in tools/)');
    process.exit(77);
}

const file = process.argv[2];
if (!file) {
    console.error('usage: node validate_gltf.js FILE.gltf');
    process.exit(2);
}
const bytes = new Uint8Array(fs.readFileSync(file));
validator.validateBytes(bytes, { uri: path.basename(file), maxIssues: 100 }).then((report) => {
    const issues = report.issues;
    console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
                `${issues.numInfos} infos, ${issues.numHints} hints`);
    for (const message of issues.messages) {
        // Severity 0 = error, 1 = warning; infos and hints are advice, not defects.
        if (message.severity <= 1) console.log(`  [${message.severity}] ${message.code} ${message.pointer || ''}: ${message.message}`);
    }
    process.exit(issues.numErrors === 0 ? 0 : 1);
}, (error) => {
    console.error(`validate_gltf: ${error}`);
    process.exit(1);
});
