// Runs the Khronos glTF validator (npm package gltf-validator, installed by scripts/setup) on one .gltf
// and prints its report as JSON: issues.numErrors, info.animationCount, ...  Usage: node gltf_validate.js FILE
const fs = require("fs");
const path = require("path");
const validator = require("gltf-validator");

const file = process.argv[2];
validator
  .validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) =>
        fs.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(data)))),
  })
  .then((report) => console.log(JSON.stringify(report)))
  .catch((error) => {
    console.error("gltf_validate: " + error);
    process.exit(3);
  });
