// The situ extension: the language (grammar, configuration, snippets) is
// declared in package.json; this starts the language server, `situ lsp`,
// over standard input and output.
"use strict";

const vscode = require("vscode");
const { LanguageClient, TransportKind } = require("vscode-languageclient/node");

let client;

function activate(context) {
  const command = vscode.workspace.getConfiguration("situ").get("server.path") || "situ";
  const server = { command, args: ["lsp"], transport: TransportKind.stdio };
  client = new LanguageClient(
    "situ",
    "situ language server",
    { run: server, debug: server },
    { documentSelector: [{ scheme: "file", language: "situ" }, { scheme: "untitled", language: "situ" }] },
  );
  context.subscriptions.push(client);
  return client.start();
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
