// Node-RED settings for tests/e2e/test_ads_node_red.py: loopback only, nothing fetched
// from the network, no telemetry, no projects. userDir, port and flow file come from the
// command line (-u, -p, the flow file argument).
'use strict';
module.exports = {
  uiHost: '127.0.0.1',
  httpAdminRoot: '/admin',
  httpNodeRoot: '/',
  credentialSecret: false,
  flowFilePretty: true,
  diagnostics: { enabled: false, ui: false },
  telemetry: { enabled: false, updateNotification: false },
  externalModules: { autoInstall: false, palette: { allowInstall: false } },
  editorTheme: { projects: { enabled: false }, tours: false },
  logging: { console: { level: 'info', metrics: false, audit: false } },
};
