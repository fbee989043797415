// The situ extension: the language (grammar, configuration, snippets) is
// declared in package.json; this starts the language server, `situ lsp`,
// over standard input and output.
"use strict";

const vscode = require("vscode");
const { LanguageClient, TransportKind } = require("vscode-languageclient/node");

let client;

function activate(context) {
  const config = vscode.workspace.getConfiguration("situ");
  const command = config.get("server.path") || "situ";
  const server = { command, args: ["lsp"], transport: TransportKind.stdio };
  client = new LanguageClient(
    "situ",
    "situ language server",
    { run: server, debug: server },
    {
      documentSelector: [{ scheme: "file", language: "situ" }, { scheme: "untitled", language: "situ" }],
      // The verdicts' budget (docs/editors.md); changes are sent as `settings.situ`.
      initializationOptions: { verdicts: config.get("verdicts") },
      synchronize: { configurationSection: "situ" },
    },
  );
  context.subscriptions.push(client);
  return client.start();
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
