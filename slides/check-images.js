// Fails (exit 1) when a built deck in build/ refers to an image that is not there.
// Run after `marp -o build/` and copying figures/ into build/ (see package.json "build").
const fs = require("fs");
const path = require("path");
const dir = path.join(__dirname, "build");
let missing = 0;
let seen = 0;
for (const file of fs.readdirSync(dir).filter((f) => f.endsWith(".html"))) {
  const html = fs.readFileSync(path.join(dir, file), "utf8");
  for (const m of html.matchAll(/(?:src="|url\(["']?)([^"')]+\.(?:png|svg|jpg))/g)) {
    const ref = m[1];
    if (/^(https?:|data:)/.test(ref)) continue;
    seen += 1;
    if (!fs.existsSync(path.join(dir, decodeURI(ref)))) {
      console.error(`${file}: missing image ${ref}`);
      missing += 1;
    }
  }
}
if (seen === 0) {
  console.error("no images found in build/*.html: was the build run?");
  process.exit(1);
}
console.log(`${seen} image references, ${missing} missing`);
process.exit(missing ? 1 : 0);
