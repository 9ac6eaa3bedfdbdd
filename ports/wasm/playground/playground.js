// The PRAY playground: a program in the editor, rendered by libpray.wasm in Web Workers.
// Each of N workers runs the whole program and renders band K of N of every frame (the rows of
// `pray --part K/N`); the page draws the rows as they come. The canvas shows the last frame.
'use strict';

const $ = (id) => document.getElementById(id);
const MEMORY_CAP = 512 * 1024 * 1024; // bytes one worker's context may hold
const TEXTURE_DIR = 'examples/';      // a program's "tex/x.tif" is fetched from examples/tex/x.tif

const state = {
    module: null,    // the compiled libpray.wasm
    textures: [],    // [name, bytes] of every texture the examples use
    includes: [],    // [name, bytes] of every program file the examples include
    workers: [],
    running: false,
    frame: -1,       // the frame on the canvas
    rows: 0,         // rows of that frame drawn
    height: 0,
    results: [],     // each worker's 'done' message
    started: 0,
};
window.playground = state; // for the tests

function setStatus(text) { $('status').textContent = text; }

// ---- the editor: line numbers, and the line of an error marked ----
function lineCount() { return $('program').value.split('\n').length; }
function drawGutter(bad) {
    const gutter = $('gutter');
    gutter.textContent = '';
    for (let i = 1; i <= lineCount(); i++) {
        const span = document.createElement('span');
        span.textContent = i + '\n';
        if (i === bad) span.className = 'bad';
        gutter.appendChild(span);
    }
    gutter.scrollTop = $('program').scrollTop;
}
function clearError() {
    $('error').textContent = '';
    $('errorline').textContent = '';
    drawGutter(0);
}
// Show a message; where it has a place (line, col from 1), mark that line and select it.
function showError(message, line, col) {
    $('error').textContent = message;
    if (line < 1) return;
    const lines = $('program').value.split('\n');
    if (line > lines.length) return;
    const text = lines[line - 1];
    $('errorline').textContent = line + ' | ' + text + '\n' + ' '.repeat(String(line).length + 3 + Math.max(col - 1, 0)) + '^';
    drawGutter(line);
    let start = 0;
    for (let i = 0; i < line - 1; i++) start += lines[i].length + 1;
    const area = $('program');
    area.focus();
    area.setSelectionRange(start, start + text.length);
    // scroll the line into view: lines are of equal height
    const lineHeight = area.scrollHeight / lines.length;
    area.scrollTop = Math.max(0, (line - 3) * lineHeight);
    $('gutter').scrollTop = area.scrollTop;
}

// ---- rendering ----
function stopWorkers() {
    for (const w of state.workers) w.terminate();
    state.workers = [];
    state.running = false;
    $('render').disabled = false;
    $('cancel').disabled = true;
}

function options() {
    const list = [];
    for (const name of ['width', 'height']) {
        const v = $(name).value.trim();
        if (v !== '') list.push([name, v]);
    }
    if ($('antialias').value) list.push(['antialias', $('antialias').value]);
    return list;
}

function render() {
    if (!state.module) return;
    stopWorkers();
    clearError();
    $('output').textContent = '';
    $('statistics').textContent = '';
    $('download').hidden = true;
    $('progress').value = 0;
    const n = Math.max(1, Math.min(16, parseInt($('workers').value, 10) || 1));
    const job = {
        module: state.module, name: $('example').value || 'program.ray', text: $('program').value,
        n, options: options(), textures: state.textures, includes: state.includes, memcap: MEMORY_CAP,
    };
    Object.assign(state, { running: true, frame: -1, rows: 0, height: 0, results: [], started: performance.now() });
    $('render').disabled = true;
    $('cancel').disabled = false;
    setStatus('Rendering with ' + n + ' worker' + (n > 1 ? 's' : '') + '...');
    for (let k = 1; k <= n; k++) {
        const w = new Worker('worker.js');
        w.onmessage = (e) => message(k, e.data);
        w.onerror = (e) => message(k, { type: 'done', status: -1, error: 'error: the worker failed: ' + e.message,
                                        line: 0, col: 0, frames: 0, stats: '', seconds: 0 });
        w.postMessage(Object.assign({ k }, job));
        state.workers.push(w);
    }
}

function message(k, m) {
    if (!state.running) return;
    if (m.type === 'rows') {
        const canvas = $('image');
        if (m.frame > state.frame) { // a new frame: a new picture
            state.frame = m.frame;
            state.rows = 0;
            state.height = m.height;
            canvas.width = m.width;
            canvas.height = m.height;
        }
        if (m.frame < state.frame) return;
        canvas.getContext('2d').putImageData(new ImageData(m.pixels, m.width, m.n), 0, m.y);
        state.rows += m.n;
        $('progress').value = state.rows / state.height;
    } else if (m.type === 'print') {
        if (k === 1) $('output').textContent += m.text; // every worker prints the same
    } else if (m.type === 'done') {
        state.results[k - 1] = m;
        if (m.status !== 0) { // one failure ends the render: show it, stop the others
            stopWorkers();
            showError(m.error, m.line, m.col);
            setStatus('Failed.');
            return;
        }
        if (state.results.filter((r) => r).length < state.workers.length) return;
        finish();
    }
}

function finish() {
    stopWorkers();
    const seconds = (performance.now() - state.started) / 1000;
    const frames = state.results[0].frames;
    $('progress').value = 1;
    if (state.frame < 0) {
        setStatus('Done in ' + seconds.toFixed(2) + ' s: the program rendered no frame.');
        return;
    }
    setStatus('Done in ' + seconds.toFixed(2) + ' s: ' + frames + ' frame' + (frames > 1 ? 's' : '') + ', ' +
              $('image').width + ' x ' + $('image').height + (frames > 1 ? ' (the last one shown)' : '') + '.');
    if ($('stats').checked) {
        $('statistics').textContent = state.results.map((r, i) =>
            'worker ' + (i + 1) + ' of ' + state.results.length + ':\n' + r.stats).join('\n');
    }
    $('image').toBlob((blob) => {
        const a = $('download');
        if (a.href.startsWith('blob:')) URL.revokeObjectURL(a.href);
        a.href = URL.createObjectURL(blob);
        a.download = ($('example').value || 'program.ray').replace(/\.ray$/, '') + '.png';
        a.hidden = false;
    }, 'image/png');
}

function cancel() {
    if (!state.running) return;
    stopWorkers();
    setStatus('Cancelled.');
}

// ---- start: the renderer, the examples and their textures ----
async function fetchOk(url) {
    const r = await fetch(url);
    if (!r.ok) throw new Error('cannot load ' + url + ': ' + r.status + ' ' + r.statusText);
    return r;
}
async function loadExample(name) {
    $('program').value = await (await fetchOk('examples/' + name)).text();
    clearError();
}
async function start() {
    $('workers').value = Math.max(1, Math.min(4, navigator.hardwareConcurrency || 2));
    $('program').addEventListener('input', () => drawGutter(0));
    $('program').addEventListener('scroll', () => { $('gutter').scrollTop = $('program').scrollTop; });
    $('render').addEventListener('click', render);
    $('program').addEventListener('keydown', (e) => {
        if (e.key === 'Enter' && (e.ctrlKey || e.metaKey) && !$('render').disabled) { e.preventDefault(); render(); }
    });
    $('cancel').addEventListener('click', cancel);
    $('example').addEventListener('change', () => loadExample($('example').value).catch((e) => showError(e.message, 0, 0)));
    try {
        const index = await (await fetchOk('examples/index.json')).json();
        for (const name of index.examples) {
            const o = document.createElement('option');
            o.textContent = name;
            $('example').appendChild(o);
        }
        $('example').value = index.examples.includes('csg.ray') ? 'csg.ray' : index.examples[0];
        const [bytes] = await Promise.all([
            fetchOk('libpray.wasm').then((r) => r.arrayBuffer()),
            loadExample($('example').value),
            ...index.textures.map(async (name) => {
                const data = new Uint8Array(await (await fetchOk(TEXTURE_DIR + name)).arrayBuffer());
                state.textures.push([name, data]);
            }),
            ...index.includes.map(async (name) => {
                const data = new Uint8Array(await (await fetchOk('examples/' + name)).arrayBuffer());
                state.includes.push([name, data]);
            }),
        ]);
        state.module = await WebAssembly.compile(bytes);
        $('render').disabled = false;
        setStatus('Ready.');
    } catch (e) {
        setStatus('The playground could not start.');
        showError('error: ' + e.message, 0, 0);
    }
}
start();
