// tests/gltf_validate.js - check glTF files (.glb, or .gltf with the files
// its URIs name beside it) with the Khronos glTF validator (the npm package
// gltf-validator).
//
//   node tests/gltf_validate.js FILE.glb|FILE.gltf...
//   node tests/gltf_validate.js --version     (is it installed? exit 0 or 2)
//
// The package is looked for in build/gltf-validator (where
// tests/ensure_deps.sh installs it), then wherever node's require finds it.
// Prints, per file, "FILE: E errors, W warnings, I infos, H hints" and every
// error and warning with its JSON pointer. Exit status: 0 when no file has
// an error, 1 when one has, 2 when the validator is not installed (the
// e2e tests then say the check was skipped) or a file cannot be read.
'use strict';
const fs = require('fs');
const path = require('path');

function loadValidator() {
    const local = path.join(__dirname, '..', 'build', 'gltf-validator', 'node_modules');
    for (const where of [local, ...(require.resolve.paths('gltf-validator') || [])]) {
        try {
            return require(require.resolve('gltf-validator', { paths: [where] }));
        } catch (e) {
            // not there: the next place
        }
    }
    return null;
}

async function main() {
    const files = process.argv.slice(2);
    if (files.length === 0) {
        console.error('usage: node tests/gltf_validate.js FILE.glb|FILE.gltf...');
        return 2;
    }
    const validator = loadValidator();
    if (!validator) {
        console.error('gltf-validator is not installed: npm install --prefix build/gltf-validator gltf-validator');
        return 2;
    }
    if (files.length === 1 && files[0] === '--version') {
        console.log(`gltf-validator ${validator.version()}`);
        return 0;
    }
    let status = 0;
    for (const file of files) {
        let bytes;
        try {
            bytes = new Uint8Array(fs.readFileSync(file));
        } catch (e) {
            console.error(`${file}: ${e.message}`);
            return 2;
        }
        // Unlimited issues: a count cut short would hide errors. A .gltf's
        // buffers and images are read from the files its relative URIs name
        // (a missing one is the validator's error to report).
        const directory = path.dirname(file);
        const external = (uri) => new Promise((resolve, reject) => {
            fs.readFile(path.join(directory, decodeURIComponent(uri)), (error, data) => {
                if (error) reject(error);
                else resolve(new Uint8Array(data));
            });
        });
        const report = await validator.validateBytes(bytes, { uri: path.basename(file), maxIssues: 0,
                                                             writeTimestamp: false,
                                                             externalResourceFunction: external });
        const issues = report.issues;
        console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
                    `${issues.numInfos} infos, ${issues.numHints} hints (gltf-validator ${validator.version()})`);
        const shown = { 0: 'error', 1: 'warning' };
        for (const message of issues.messages)
            if (message.severity in shown)
                console.log(`  ${shown[message.severity]} ${message.code} at ${message.pointer || '/'}: ${message.message}`);
        if (issues.numErrors > 0) status = 1;
    }
    return status;
}

main().then((status) => { process.exitCode = status; },
            (error) => { console.error(`gltf-validator failed: ${error}`); process.exitCode = 2; });
