// Starts `eamos lsp` for .eamos files and connects VS Code to it over standard input and
// output. Everything the editor shows beyond highlighting comes from the server.
'use strict';
const vscode = require('vscode');
const { LanguageClient, TransportKind } = require('vscode-languageclient/node');

let client;

function activate(context) {
  const config = vscode.workspace.getConfiguration('eamos');
  const command = config.get('server.path', 'eamos');
  const fleet = config.get('fleet', '');
  const serverOptions = { command, args: ['lsp'], transport: TransportKind.stdio };
  const clientOptions = {
    documentSelector: [
      { scheme: 'file', language: 'eamos' },
      { scheme: 'untitled', language: 'eamos' },
    ],
    // A relative fleet path is resolved by the server against the workspace folder.
    initializationOptions: fleet ? { fleet } : {},
  };
  client = new LanguageClient('eamos', 'eamos', serverOptions, clientOptions);
  context.subscriptions.push(
    vscode.workspace.onDidChangeConfiguration((e) => {
      if (e.affectsConfiguration('eamos')) {
        vscode.window.showInformationMessage('eamos: reload the window to use the new settings.');
      }
    }),
  );
  return client.start();
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
