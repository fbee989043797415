// Tokenizes every .situ file named on standard input (one path a line)
// with the extension's grammar and checks that the grammar covers the
// language's whole lexicon: every keyword outside comments and strings is
// scoped as one, and every other character is whitespace, a name, or
// scoped by the grammar. Exits 1 on the first file that fails, with where.
"use strict";

const fs = require("fs");
const path = require("path");
const vsctm = require("vscode-textmate");
const oniguruma = require("vscode-oniguruma");

// The keywords of the language (grammar/src/parse.rs, KEYWORDS) and the words of scripts.
const KEYWORDS = new Set(
  ("states agent rule test property include initial final sensor actuator processing interface " +
    "stale after event function table fsm rate when then salience and or not in state within run sleep wait " +
    "from to on given expect at link no always never next eventually events true false " +
    "runs running sleeping waiting f64 i64 bool").split(" "),
);

async function main() {
  const wasm = fs.readFileSync(require.resolve("vscode-oniguruma/release/onig.wasm"));
  await oniguruma.loadWASM(wasm.buffer.slice(wasm.byteOffset, wasm.byteOffset + wasm.byteLength));
  const registry = new vsctm.Registry({
    onigLib: Promise.resolve({
      createOnigScanner: (p) => new oniguruma.OnigScanner(p),
      createOnigString: (s) => new oniguruma.OnigString(s),
    }),
    loadGrammar: async () => {
      const file = path.join(__dirname, "..", "syntaxes", "situ.tmLanguage.json");
      return vsctm.parseRawGrammar(fs.readFileSync(file, "utf8"), file);
    },
  });
  const grammar = await registry.loadGrammar("source.situ");
  const files = fs.readFileSync(0, "utf8").split("\n").filter((f) => f.trim() !== "");
  if (files.length === 0) {
    console.error("no .situ file to check");
    process.exit(1);
  }
  let lines = 0;
  for (const file of files) {
    const text = fs.readFileSync(file, "utf8");
    let stack = vsctm.INITIAL;
    text.split("\n").forEach((line, n) => {
      const r = grammar.tokenizeLine(line, stack);
      stack = r.ruleStack;
      lines += 1;
      for (const t of r.tokens) {
        const piece = line.slice(t.startIndex, t.endIndex);
        const inner = t.scopes.slice(1);
        const where = `${file}:${n + 1}:${t.startIndex + 1}: \`${piece}\``;
        const quoted = inner.some((s) => s.startsWith("comment") || s.startsWith("string"));
        if (quoted) continue;
        // Split a plain run into words and other characters.
        if (inner.length === 0) {
          for (const m of piece.matchAll(/[A-Za-z_][A-Za-z0-9_]*|\S/g)) {
            const w = m[0];
            if (KEYWORDS.has(w)) fail(`${where}: the keyword \`${w}\` has no scope`);
            if (!/^[A-Za-z_]/.test(w)) fail(`${where}: \`${w}\` has no scope`);
          }
        } else if (KEYWORDS.has(piece) && !inner.some((s) => /^(storage|keyword|variable\.language|constant\.language|support\.type)/.test(s))) {
          fail(`${where}: the keyword is scoped ${inner.join(" ")}`);
        }
      }
    });
  }
  console.log(`the grammar covers ${files.length} files, ${lines} lines`);
}

function fail(message) {
  console.error(message);
  process.exit(1);
}

main().catch((e) => fail(String(e && e.stack ? e.stack : e)));
