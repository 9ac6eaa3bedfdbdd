// The playground's worker: runs one PRAY program in libpray.wasm and renders band K of N of each
// of its frames (as `pray --part K/N` does), handing the rows to the page as they come.
//
// In:  {module, name, text, k, n, options: [[name, value], ...], textures: [[name, bytes], ...],
//       includes: [[name, bytes], ...], memcap}
// Out: {type: 'rows', frame, y, n, width, height, pixels}   8-bit RGBA, rows y .. y+n-1
//      {type: 'print', text}                                what the program printed
//      {type: 'done', status, error, line, col, frames, stats, seconds}
'use strict';

// The few calls of WASI (preview 1) the library makes: a clock, and writes to standard output
// and error (which it makes only in a failure of its own). Every other call fails with ENOSYS.
const ENOSYS = 52, EBADF = 8, ESPIPE = 70;
function wasiImports(module, memory) {
    const decoder = new TextDecoder();
    const own = {
        clock_time_get(id, precision, out) {
            const ns = BigInt(Math.round(performance.now() * 1e6));
            new DataView(memory().buffer).setBigUint64(out, ns, true);
            return 0;
        },
        fd_write(fd, iovs, count, written) {
            const view = new DataView(memory().buffer);
            let text = '', total = 0;
            for (let i = 0; i < count; i++) {
                const ptr = view.getUint32(iovs + 8 * i, true), len = view.getUint32(iovs + 8 * i + 4, true);
                text += decoder.decode(new Uint8Array(memory().buffer, ptr, len));
                total += len;
            }
            if (fd !== 1 && fd !== 2) return EBADF;
            console.log(text);
            view.setUint32(written, total, true);
            return 0;
        },
        fd_close() { return 0; },
        fd_seek() { return ESPIPE; },
        proc_exit(code) { throw new Error('the library exited with status ' + code); },
    };
    const imports = {};
    for (const imp of WebAssembly.Module.imports(module)) {
        if (imp.module !== 'wasi_snapshot_preview1') continue;
        imports[imp.name] = own[imp.name] || (() => ENOSYS);
    }
    return imports;
}

async function run(job) {
    let exports = null;
    const memory = () => exports.memory;
    const decoder = new TextDecoder();
    const env = {
        pg_rows(frame, y, n, width, height, ptr) {
            const pixels = new Uint8ClampedArray(memory().buffer.slice(ptr, ptr + width * n * 4));
            postMessage({ type: 'rows', frame, y, n, width, height, pixels }, [pixels.buffer]);
        },
        pg_print(ptr, len) {
            postMessage({ type: 'print', text: decoder.decode(new Uint8Array(memory().buffer, ptr, len)) });
        },
    };
    const instance = await WebAssembly.instantiate(job.module, {
        env, wasi_snapshot_preview1: wasiImports(job.module, memory) });
    exports = instance.exports;
    exports._initialize();
    const encoder = new TextEncoder();
    // bytes into the library's memory; the page's strings end with a 0 byte
    const put = (bytes, zero) => {
        const p = exports.pg_alloc(bytes.length + 1);
        if (!p) throw new Error('out of memory');
        const mem = new Uint8Array(memory().buffer);
        mem.set(bytes, p);
        if (zero) mem[p + bytes.length] = 0;
        return p;
    };
    const str = (s) => put(encoder.encode(s), true);
    const cstr = (p) => {
        const mem = new Uint8Array(memory().buffer);
        let e = p;
        while (mem[e]) e++;
        return decoder.decode(mem.subarray(p, e));
    };
    const done = (status) => postMessage({
        type: 'done', status, error: status ? cstr(exports.pg_error()) : '',
        line: exports.pg_error_line(), col: exports.pg_error_col(), frames: exports.pg_frames(),
        stats: cstr(exports.pg_stats()), seconds: (performance.now() - t0) / 1000 });
    const t0 = performance.now();
    let st = exports.pg_new(job.memcap);
    if (st) throw new Error('no memory for a context');
    for (const [name, value] of job.options) {
        st = exports.pg_option(str(name), str(String(value)));
        if (st) return done(st);
    }
    for (const [name, bytes] of job.textures) {
        st = exports.pg_texture(str(name), put(bytes, false), bytes.length);
        if (st) return done(st);
    }
    for (const [name, bytes] of job.includes) {
        st = exports.pg_include(str(name), put(bytes, false), bytes.length);
        if (st) return done(st);
    }
    const text = encoder.encode(job.text);
    st = exports.pg_run(str(job.name), put(text, false), text.length, job.k, job.n);
    done(st);
}

onmessage = (e) => {
    run(e.data).catch((err) => {
        let why = 'error: the renderer stopped: ' + (err && err.message || err);
        if (err instanceof RangeError && /stack/.test(err.message)) {
            why += ' (the browser gives a worker less stack than the deepest CSG trees need)';
        }
        postMessage({ type: 'done', status: -1, error: why, line: 0, col: 0, frames: 0, stats: '', seconds: 0 });
    });
};
