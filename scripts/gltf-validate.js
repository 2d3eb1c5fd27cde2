#!/usr/bin/env node
// gltf-validate.js FILE.glb: runs the Khronos glTF validator (npm gltf-validator) on FILE and
// prints its issue counts and messages as JSON. Exit 0: no error; 1: errors; 3: the validator
// module is not installed (npm install -g gltf-validator; NODE_PATH=$(npm root -g)).
'use strict';
const fs = require('fs');
const path = require('path');
let validator;
try {
  validator = require('gltf-validator');
} catch (e) {
  console.error('gltf-validator is not installed');
  process.exit(3);
}
const file = process.argv[2];
const bytes = new Uint8Array(fs.readFileSync(file));
validator.validateBytes(bytes, {
  uri: path.basename(file),
  maxIssues: 50,
  externalResourceFunction: (uri) => new Promise((resolve, reject) => {
    fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, data) => {
      if (err) reject(err.toString()); else resolve(new Uint8Array(data));
    });
  }),
}).then((report) => {
  const i = report.issues;
  console.log(JSON.stringify({numErrors: i.numErrors, numWarnings: i.numWarnings, numInfos: i.numInfos,
                              messages: i.messages.filter((m) => m.severity <= 1)}));
  process.exit(i.numErrors ? 1 : 0);
}).catch((e) => {
  console.error('validator failed: ' + e);
  process.exit(2);
});
