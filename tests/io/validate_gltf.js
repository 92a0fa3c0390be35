// Validate a glTF/GLB file with the Khronos glTF validator; print the report's issue counts as JSON.
// usage: node validate_gltf.js FILE   (NODE_PATH must reach the gltf-validator package)
const fs = require("fs");
const path = require("path");
const validator = require("gltf-validator");
const file = process.argv[2];
const data = new Uint8Array(fs.readFileSync(file));
validator
  .validateBytes(data, {
    uri: path.basename(file),
    maxIssues: 0,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, d) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(d))
        );
      }),
  })
  .then((r) => {
    const msgs = r.issues.messages.filter((m) => m.severity === 0).map((m) => `${m.code} ${m.pointer}: ${m.message}`);
    console.log(JSON.stringify({ errors: r.issues.numErrors, warnings: r.issues.numWarnings, messages: msgs.slice(0, 20) }));
  })
  .catch((e) => {
    console.log(JSON.stringify({ errors: -1, messages: [String(e)] }));
  });
