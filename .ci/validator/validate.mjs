// Validates every .glb/.gltf under the given folders with the Khronos glTF validator.
// Exits 1 on any error, or when there is nothing to validate (a silent pass would hide a
// test suite that stopped writing files).
import { readFileSync, readdirSync, statSync } from "node:fs";
import { join, dirname } from "node:path";
import validator from "gltf-validator";

const files = [];
function walk(p) {
  if (statSync(p).isDirectory()) {
    for (const e of readdirSync(p)) walk(join(p, e));
  } else if (/\.(glb|gltf)$/i.test(p)) {
    files.push(p);
  }
}
for (const dir of process.argv.slice(2)) walk(dir);
if (files.length === 0) {
  console.error("validate: no glTF files found in", process.argv.slice(2).join(" "));
  process.exit(1);
}
let failed = 0;
for (const f of files.sort()) {
  const bytes = new Uint8Array(readFileSync(f));
  const report = await validator.validateBytes(bytes, {
    uri: f,
    maxIssues: 20,
    externalResourceFunction: (uri) =>
      new Promise((ok, fail) => {
        try { ok(new Uint8Array(readFileSync(join(dirname(f), decodeURIComponent(uri))))); }
        catch (e) { fail(e.toString()); }
      }),
  });
  const n = report.issues.numErrors;
  const w = report.issues.numWarnings;
  if (n > 0) {
    failed++;
    console.log(`FAIL ${f}: ${n} errors, ${w} warnings`);
    for (const m of report.issues.messages.filter((m) => m.severity === 0)) {
      console.log(`     ${m.code} ${m.pointer ?? ""}: ${m.message}`);
    }
  } else {
    console.log(`ok   ${f} (${w} warnings)`);
  }
}
console.log(`glTF validation: ${files.length - failed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
