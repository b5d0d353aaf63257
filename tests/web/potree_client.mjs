#!/usr/bin/env node
// Loads a Potree 2.0 folder in a real Potree client and prints what it loaded, as one JSON line:
//   node tests/web/potree_client.mjs --cloud DIR [--screenshot OUT.png] [--timeout-ms 45000]
// A loopback HTTP server (this process; Range requests, which Potree's loader sends for every
// node) serves the page, the npm packages and DIR under /cloud/; headless Chromium (Debian's,
// WebGL 2 through SwiftShader) runs potree_client_page.mjs, which fits the camera, loads with an
// unlimited point budget until loading settles and reports the counts; the canvas goes to
// OUT.png. Exit status: 0 reported (the caller judges the numbers), 1 the page failed,
// 77 Chromium or the npm packages are missing (the test is skipped, not failed).
import {createServer} from 'node:http';
import {createReadStream, existsSync, statSync} from 'node:fs';
import path from 'node:path';
import {fileURLToPath} from 'node:url';

const kSkip = 77;
const here = path.dirname(fileURLToPath(import.meta.url));

function parseArgs(argv) {
    const args = {timeoutMs: 45000};
    for (let i = 0; i < argv.length; i += 2) {
        const [name, value] = [argv[i], argv[i + 1]];
        if (value === undefined) {
            throw new Error(`${name} needs a value`);
        }
        if (name === '--cloud') args.cloud = path.resolve(value);
        else if (name === '--screenshot') args.screenshot = path.resolve(value);
        else if (name === '--timeout-ms') args.timeoutMs = Number(value);
        else throw new Error(`unknown option ${name}`);
    }
    if (!args.cloud) {
        throw new Error('--cloud DIR is required');
    }
    return args;
}

function skip(reason) {
    console.log(JSON.stringify({skipped: reason}));
    process.exit(kSkip);
}

const kTypes = {'.html': 'text/html', '.mjs': 'text/javascript', '.js': 'text/javascript',
                '.json': 'application/json', '.bin': 'application/octet-stream'};

// Static files under `roots` (URL prefix -> folder), with single byte ranges: enough for the
// page, the ES modules and Potree's octree.bin/hierarchy.bin requests.
function serve(roots) {
    return createServer((request, response) => {
        const url = decodeURIComponent(new URL(request.url, 'http://localhost').pathname);
        const prefix = Object.keys(roots).find((p) => url.startsWith(p));
        const file = prefix && path.join(roots[prefix], url.slice(prefix.length));
        if (!file || !file.startsWith(roots[prefix]) || !existsSync(file) ||
            !statSync(file).isFile()) {
            response.writeHead(404).end();
            return;
        }
        const size = statSync(file).size;
        const headers = {'Content-Type': kTypes[path.extname(file)] || 'application/octet-stream',
                         'Accept-Ranges': 'bytes', 'Cache-Control': 'no-store'};
        const range = /^bytes=(\d+)-(\d*)$/.exec(request.headers.range || '');
        if (range) {
            const start = Number(range[1]);
            const end = range[2] === '' ? size - 1 : Math.min(Number(range[2]), size - 1);
            if (start > end) {
                response.writeHead(416, {'Content-Range': `bytes */${size}`}).end();
                return;
            }
            response.writeHead(206, {...headers, 'Content-Range': `bytes ${start}-${end}/${size}`,
                                     'Content-Length': end - start + 1});
            createReadStream(file, {start, end}).pipe(response);
            return;
        }
        response.writeHead(200, {...headers, 'Content-Length': size});
        createReadStream(file).pipe(response);
    });
}

async function main() {
    const args = parseArgs(process.argv.slice(2));
    const executablePath = process.env.OMICRON_CHROMIUM || '/usr/bin/chromium';
    if (!existsSync(executablePath)) {
        skip(`no Chromium at ${executablePath} (scripts/build.sh installs Debian's chromium)`);
    }
    for (const module of ['potree-core', 'three', 'playwright-core']) {
        if (!existsSync(path.join(here, 'node_modules', module))) {
            skip(`npm package ${module} missing in ${here}/node_modules (scripts/build.sh runs npm ci)`);
        }
    }
    const {chromium} = await import('playwright-core');

    const server = serve({'/cloud/': args.cloud, '/': here});
    await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
    const port = server.address().port;
    let browser;
    try {
        try {
            browser = await chromium.launch({
                executablePath,
                args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
                       '--ignore-gpu-blocklist'],
            });
        } catch (error) {
            skip(`Chromium did not start: ${String(error.message).split('\n')[0]}`);
        }
        const page = await browser.newPage({viewport: {width: 1280, height: 800}});
        const console_ = [];
        page.on('console', (message) => console_.push(`${message.type()}: ${message.text()}`));
        page.on('pageerror', (error) => console_.push(`pageerror: ${error.message}`));
        await page.goto(`http://127.0.0.1:${port}/potree_client.html?timeoutMs=${args.timeoutMs}`);
        await page.waitForFunction(() => window.potreeResult !== undefined, null,
                                   {timeout: args.timeoutMs + 10000});
        const result = await page.evaluate(() => window.potreeResult);
        if (args.screenshot) {
            await page.locator('#view').screenshot({path: args.screenshot});
            result.screenshot = args.screenshot;
        }
        // The loader warns once per node stored with no point; the rest is worth seeing.
        result.console = console_.filter((line) => !line.includes('loaded node with 0 bytes'))
                                 .slice(0, 20);
        console.log(JSON.stringify(result));
        process.exitCode = result.ok ? 0 : 1;
    } finally {
        if (browser) {
            await browser.close();
        }
        server.close();
    }
}

main().catch((error) => {
    console.log(JSON.stringify({ok: false, error: String(error && error.stack || error)}));
    process.exit(1);
});
