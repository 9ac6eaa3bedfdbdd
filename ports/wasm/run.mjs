// ports/wasm/run.mjs — run a wasm32-wasi program under Node's WASI, with the current directory
// (relative paths; absolute ones are not reachable) open to it:
//     node --experimental-wasi-unstable-preview1 ports/wasm/run.mjs ports/build/wasm/pray.wasm \
//         -s 64x64 -o out.ppm examples/csg.ray
// (Node 18, Debian 12's, needs the option; later versions accept it.)
// Exits with the program's status.
import { readFileSync } from 'node:fs';
import { WASI } from 'node:wasi';
import process from 'node:process';

const [file, ...args] = process.argv.slice(2);
if (!file) {
    process.stderr.write('usage: node ports/wasm/run.mjs PROGRAM.wasm [ARGUMENTS...]\n');
    process.exit(2);
}
const wasi = new WASI({ version: 'preview1', args: ['pray', ...args], env: {}, preopens: { '.': '.' },
                        returnOnExit: true });
const module = await WebAssembly.compile(readFileSync(file));
const instance = await WebAssembly.instantiate(module, { wasi_snapshot_preview1: wasi.wasiImport });
process.exitCode = wasi.start(instance);
