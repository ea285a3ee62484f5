// Loads npm modules from the folder scripts/setup installs them into (.tools/node_modules at the
// top of the repository, ignored by git). ES module resolution only looks in node_modules folders
// above the importing file, so the path is resolved explicitly; DPOINT_NODE_MODULES overrides it.
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
export const modulesDir =
  process.env.DPOINT_NODE_MODULES || path.resolve(here, '../../../.tools/node_modules');
const require = createRequire(path.join(modulesDir, 'resolve-from-here.js'));

export async function load(specifier) {
  let resolved;
  try {
    resolved = require.resolve(specifier);
  } catch (e) {
    // Fail loudly: a missing module is a setup error, never a reason to skip a check.
    throw new Error(`npm module ${specifier} not found under ${modulesDir} (run scripts/setup)`);
  }
  return import(pathToFileURL(resolved).href);
}

// Shortest text that reads back as the same double (like Python's repr), so no precision is lost.
export const num = (x) => String(x);
