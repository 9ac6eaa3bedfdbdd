// ports/wasm/playground-check.mjs — the playground in a real browser (make playground-check):
// headless Chromium, driven by puppeteer-core, opens the built page (ports/build/playground,
// served here by a small static server on 127.0.0.1) and
//  1. renders examples/csg.ray at 160x125 in 3 workers and compares the canvas, pixel for
//     pixel, with the PPM the native ./pray writes (-s 160x125), and the PNG offered for
//     download with the canvas;
//  2. runs a program with an error and checks the message (the native program's, word for
//     word), the line marked in the editor and the text selected;
//  3. starts a long render (fractal.ray at 1024x1024, antialias 4), cancels it after its first
//     rows and checks that the workers are gone and that none sends a row afterwards;
//  4. renders the red sphere (examples/redsph.ray, antialias 2, 2 workers, statistics) and
//     compares it with ./pray -D antialias=2, and the statistics shown;
//  5. renders examples/street.ray, which includes parts/house.ray (a text the page lends the
//     renderer), at 120x80 in 2 workers, and compares it with ./pray -s 120x80;
//  6. renders csg.ray at 1024x1024 in 1 worker, timed against the native program (1 thread).
// Environment: CHROMIUM (default /usr/bin/chromium), PUPPETEER (the puppeteer-core module's
// directory). Ends with "N passed, N failed"; exit status 1 when any check failed.
import { createServer } from 'node:http';
import { readFileSync, writeFileSync, existsSync, mkdirSync } from 'node:fs';
import { execFileSync } from 'node:child_process';
import { join, extname, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import process from 'node:process';

const SITE = 'ports/build/playground';
const WORK = 'ports/build/playground-check';
const { default: puppeteer } = await import(pathToFileURL(join(resolve(process.env.PUPPETEER ||
    'ports/build/npm/node_modules/puppeteer-core'), 'lib/esm/puppeteer/puppeteer-core.js')).href);

let passed = 0, failed = 0;
function check(ok, what, detail) {
    if (ok) passed++; else failed++;
    console.log((ok ? 'ok     ' : 'FAILED ') + what + (detail ? ': ' + detail : ''));
}

// ---- the native references ----
mkdirSync(WORK, { recursive: true });
function native(args) {
    const t0 = performance.now();
    execFileSync('./pray', ['--quiet', ...args], { stdio: ['ignore', 'ignore', 'pipe'] });
    return (performance.now() - t0) / 1000;
}
// the RGB samples of a binary 8-bit PPM
function readPPM(path) {
    const b = readFileSync(path);
    const head = b.toString('latin1', 0, 64).match(/^P6\s+(?:#[^\n]*\n\s*)*(\d+)\s+(\d+)\s+(\d+)\s/);
    if (!head || head[3] !== '255') throw new Error(path + ': not an 8-bit PPM');
    return { width: +head[1], height: +head[2], rgb: b.subarray(head[0].length) };
}
native(['-s', '160x125', '-o', WORK + '/csg.ppm', 'examples/csg.ray']);
native(['-D', 'antialias=2', '-o', WORK + '/redsph.ppm', 'examples/redsph.ray']);
native(['-s', '120x80', '-o', WORK + '/street.ppm', 'examples/street.ray']);
const nativeSeconds = Math.min(...[1, 2, 3].map(() =>
    native(['-D', 'threads=1', '-s', '1024x1024', '-o', WORK + '/csg-1024.ppm', 'examples/csg.ray'])));
const BAD = 'A = 1\nB = [1, 2, 3]\nC = (2 +\nrendertiff C, none\n';
// the native program's message for the same text under the same name (the page keeps the
// example's name)
let nativeError = '';
writeFileSync(WORK + '/csg.ray', BAD);
try {
    execFileSync(resolve('pray'), ['--quiet', '--untrusted', 'csg.ray'], { cwd: WORK, stdio: 'pipe' });
} catch (e) {
    nativeError = e.stderr.toString().trim();
}

// ---- a static file server for the site ----
const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.json': 'application/json',
                '.wasm': 'application/wasm', '.ray': 'text/plain', '.tif': 'image/tiff' };
const server = createServer((req, res) => {
    const path = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    const file = join(SITE, path.endsWith('/') ? path + 'index.html' : path);
    if (path.includes('..') || !existsSync(file)) {
        res.writeHead(404);
        res.end('not found');
        return;
    }
    res.writeHead(200, { 'Content-Type': TYPES[extname(file)] || 'application/octet-stream' });
    res.end(readFileSync(file));
});
await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
const url = 'http://127.0.0.1:' + server.address().port + '/';

const browser = await puppeteer.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
});
const timer = setTimeout(() => { console.log('FAILED: the check took more than 10 minutes'); process.exit(1); }, 600000);
try {
    const page = await browser.newPage();
    const pageErrors = [];
    page.on('pageerror', (e) => pageErrors.push(e.message));
    // count the rows every worker sends, whatever the page does with them
    await page.evaluateOnNewDocument(() => {
        const Base = window.Worker;
        window.rowMessages = 0;
        window.Worker = class extends Base {
            constructor(...args) {
                super(...args);
                this.addEventListener('message', (e) => { if (e.data.type === 'rows') window.rowMessages++; });
            }
        };
    });
    await page.goto(url);
    await page.waitForFunction(() => document.getElementById('status').textContent === 'Ready.', { timeout: 60000 });
    check(true, 'the page loads the renderer, the examples and the textures');

    const set = (id, value) => page.$eval('#' + id, (e, v) => {
        if (e.type === 'checkbox') e.checked = v; else e.value = v;
    }, value);
    // pick an example and wait until the editor holds its text
    const choose = async (name) => {
        await page.select('#example', name);
        await page.waitForFunction((t) => document.getElementById('program').value === t, { polling: 50 },
                                   readFileSync('examples/' + name, 'utf8'));
    };
    const renderAndWait = async () => {
        await page.click('#render');
        await page.waitForFunction(() => !window.playground.running, { timeout: 300000 });
        return page.$eval('#status', (e) => e.textContent);
    };
    // the canvas as RGB samples
    const canvasRGB = () => page.evaluate(() => {
        const c = document.getElementById('image');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        const rgb = [];
        for (let i = 0; i < d.length; i += 4) rgb.push(d[i], d[i + 1], d[i + 2]);
        return { width: c.width, height: c.height, rgb };
    });
    const compare = (got, want, what) => {
        if (got.width !== want.width || got.height !== want.height) {
            check(false, what, `canvas ${got.width}x${got.height}, native ${want.width}x${want.height}`);
            return;
        }
        let diff = 0, first = -1;
        for (let i = 0; i < want.rgb.length; i++) {
            if (got.rgb[i] !== want.rgb[i]) { diff++; if (first < 0) first = i; }
        }
        check(diff === 0, what, diff ? `${diff} samples differ, the first at pixel ${Math.floor(first / 3)}`
                                     : `${want.width}x${want.height}, every sample equal`);
    };

    // 1. csg.ray in 3 bands
    await choose('csg.ray');
    await set('width', '160');
    await set('height', '125');
    await set('workers', '3');
    let status = await renderAndWait();
    check(status.startsWith('Done'), 'csg.ray renders in 3 workers', status);
    const csg = await canvasRGB();
    compare(csg, readPPM(WORK + '/csg.ppm'), 'csg.ray at 160x125 in 3 workers equals ./pray -s 160x125');
    const png = await page.evaluate(async () => {
        const a = document.getElementById('download');
        for (let i = 0; i < 100 && (a.hidden || !a.href.startsWith('blob:')); i++) await new Promise((ok) => setTimeout(ok, 50));
        if (a.hidden) return null;
        const bitmap = await createImageBitmap(await (await fetch(a.href)).blob());
        const c = new OffscreenCanvas(bitmap.width, bitmap.height);
        c.getContext('2d').drawImage(bitmap, 0, 0);
        const d = c.getContext('2d').getImageData(0, 0, bitmap.width, bitmap.height).data;
        const rgb = [];
        for (let i = 0; i < d.length; i += 4) rgb.push(d[i], d[i + 1], d[i + 2]);
        return { width: bitmap.width, height: bitmap.height, rgb, name: a.download };
    });
    check(png && png.name === 'csg.png', 'a PNG is offered for download as csg.png', png ? png.name : 'no link');
    if (png) compare(png, readPPM(WORK + '/csg.ppm'), 'the PNG download holds the same pixels');

    // 2. an error: message, marked line, selection
    await set('program', BAD);
    status = await renderAndWait();
    const err = await page.evaluate(() => {
        const area = document.getElementById('program');
        const bad = document.querySelector('#gutter .bad');
        return { message: document.getElementById('error').textContent, marked: bad ? bad.textContent.trim() : '',
                 selected: area.value.substring(area.selectionStart, area.selectionEnd),
                 caret: document.getElementById('errorline').textContent };
    });
    check(nativeError !== '' && err.message === nativeError, 'the error is the native program\'s message',
          JSON.stringify(err.message) + ' vs ' + JSON.stringify(nativeError));
    check(/:3:9: error: /.test(err.message), 'the message has its line:col', err.message);
    check(err.marked === '3', 'line 3 is marked in the editor', 'marked: ' + JSON.stringify(err.marked));
    check(err.selected === 'C = (2 +', 'line 3 is selected in the editor', JSON.stringify(err.selected));
    check(err.caret === '3 | C = (2 +\n            ^', 'the line is shown with a caret under column 9', JSON.stringify(err.caret));

    // 3. cancel a long render
    await choose('fractal.ray');
    await set('width', '1024');
    await set('height', '1024');
    await set('antialias', '4');
    await set('workers', '2');
    await page.click('#render');
    await page.waitForFunction(() => window.playground.rows > 0, { timeout: 60000 });
    await page.click('#cancel');
    await new Promise((ok) => setTimeout(ok, 200));
    const atCancel = await page.evaluate(() => ({ rows: window.playground.rows, height: window.playground.height,
                                                  sent: window.rowMessages }));
    await new Promise((ok) => setTimeout(ok, 2000));
    const after = await page.evaluate(() => ({
        rows: window.playground.rows, sent: window.rowMessages, workers: window.playground.workers.length, running: window.playground.running,
        status: document.getElementById('status').textContent, render: document.getElementById('render').disabled }));
    check(atCancel.rows < atCancel.height / 2, 'the long render was cancelled early', `${atCancel.rows} of ${atCancel.height} rows`);
    check(after.status === 'Cancelled.' && !after.running && after.workers === 0 && !after.render,
          'Cancel stops the workers and gives Render back', JSON.stringify(after));
    check(after.rows === atCancel.rows && after.sent === atCancel.sent, 'no worker sends a row after Cancel',
          `rows drawn ${atCancel.rows} then ${after.rows}, sent ${atCancel.sent} then ${after.sent}`);

    // 4. the red sphere, antialias 2, after the cancelled render, with statistics
    await choose('redsph.ray');
    await set('width', '');
    await set('height', '');
    await set('antialias', '2');
    await set('workers', '2');
    await set('stats', true);
    status = await renderAndWait();
    check(status.startsWith('Done'), 'redsph.ray renders after a cancelled render', status);
    compare(await canvasRGB(), readPPM(WORK + '/redsph.ppm'), 'redsph.ray, antialias 2, in 2 workers equals ./pray -D antialias=2');
    const stats = await page.$eval('#statistics', (e) => e.textContent);
    check(/^worker 1 of 2:\nprimitives: 1 declared, 1 kept/.test(stats) && /worker 2 of 2:/.test(stats),
          'the statistics of both workers are shown', JSON.stringify(stats.split('\n').slice(0, 2).join(' / ')));

    // 5. a program that includes another
    await choose('street.ray');
    await set('width', '120');
    await set('height', '80');
    await set('antialias', '');
    await set('stats', false);
    status = await renderAndWait();
    check(status.startsWith('Done'), 'street.ray (include "parts/house.ray") renders', status);
    compare(await canvasRGB(), readPPM(WORK + '/street.ppm'), 'street.ray at 120x80 in 2 workers equals ./pray -s 120x80');

    // 6. csg.ray at 1024x1024 in one worker, timed
    await choose('csg.ray');
    await set('width', '1024');
    await set('height', '1024');
    await set('antialias', '');
    await set('workers', '1');
    await set('stats', false);
    const t0 = Date.now();
    status = await renderAndWait();
    const browserSeconds = (Date.now() - t0) / 1000;
    compare(await canvasRGB(), readPPM(WORK + '/csg-1024.ppm'), 'csg.ray at 1024x1024 in 1 worker equals ./pray -s 1024x1024');
    console.log(`time: csg.ray 1024x1024, Chromium 1 worker ${browserSeconds.toFixed(2)} s (page: ${status}); native 1 thread ${nativeSeconds.toFixed(2)} s`);
    check(pageErrors.length === 0, 'no error in the page\'s scripts', pageErrors.join('; '));
} catch (e) {
    check(false, 'the check ran to its end', e.stack || String(e));
} finally {
    clearTimeout(timer);
    await browser.close();
    server.close();
}
console.log(`playground-check: ${passed} passed, ${failed} failed`);
process.exitCode = failed ? 1 : 0;
