#!/usr/bin/env node
// Validates .glb / .gltf files with the Khronos glTF-Validator (npm package `gltf-validator`).
//
// Usage:
//   node eval/validate_gltf.mjs FILE.glb [FILE.gltf ...]
// or, to write the crate's glTF outputs of spot, horse and an odd mesh and run this on them:
//   cargo run --release --example validate_gltf -- OUT_DIR
//
// Prints, for each file, the counts of errors, warnings, infos and hints and every issue
// (severity, code, JSON pointer, message). Exit code: 0 when no file has an error, 1 when any
// file has an error (or cannot be read), 2 when the validator is not installed.
//
// The validator is not a dependency of the crate (`cargo test` does not need it). Install it
// outside the repository and point this script at it, e.g.:
//   mkdir -p /tmp/gv && cd /tmp/gv && npm init -y && npm i gltf-validator
//   GLTF_VALIDATOR_DIR=/tmp/gv node eval/validate_gltf.mjs out.glb
// (`NODE_PATH=/tmp/gv/node_modules` works too.)

import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";

function loadValidator() {
  const candidates = [];
  if (process.env.GLTF_VALIDATOR_DIR) {
    candidates.push(path.resolve(process.env.GLTF_VALIDATOR_DIR, "package.json"));
  }
  candidates.push(import.meta.url);
  for (const base of candidates) {
    try {
      return createRequire(base)("gltf-validator");
    } catch (_) {
      // try the next place
    }
  }
  console.error(
    "gltf-validator is not installed: run `npm i gltf-validator` in a scratch folder and set " +
      "GLTF_VALIDATOR_DIR to that folder (or NODE_PATH to its node_modules)."
  );
  process.exit(2);
}

const SEVERITY = ["error", "warning", "info", "hint"];

async function validateFile(validator, file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const dir = path.dirname(file);
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,
    // External buffers / images of a .gltf, relative to the file.
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.resolve(dir, decodeURIComponent(uri)), (err, data) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(data))
        );
      }),
  });
  const issues = report.issues;
  console.log(
    `${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
      `${issues.numInfos} infos, ${issues.numHints} hints` +
      (report.info && report.info.generator ? ` (generator: ${report.info.generator})` : "")
  );
  for (const m of issues.messages) {
    const sev = SEVERITY[m.severity] ?? String(m.severity);
    console.log(`  ${sev} ${m.code} ${m.pointer ?? ""}: ${m.message}`);
  }
  return issues.numErrors;
}

async function main() {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error("usage: node eval/validate_gltf.mjs FILE.glb [FILE.gltf ...]");
    process.exit(2);
  }
  const validator = loadValidator();
  let failed = false;
  for (const file of files) {
    try {
      if ((await validateFile(validator, file)) > 0) failed = true;
    } catch (e) {
      console.log(`${file}: cannot validate: ${e}`);
      failed = true;
    }
  }
  process.exit(failed ? 1 : 0);
}

main();
