// The page half of the Potree client test (see potree_client.html). Everything it measures
// comes from potree-core itself: the nodes its visibility pass keeps (numVisiblePoints, which
// Potree viewers show as the points loaded) and the points its decoder worker delivered for
// each of them (the position attribute of each node's geometry).
import * as THREE from 'three';
import {PointSizeType, Potree} from '/node_modules/potree-core/dist/index.js';

const params = new URLSearchParams(location.search);
const width = Number(params.get('width') || 1280);
const height = Number(params.get('height') || 800);
const timeoutMs = Number(params.get('timeoutMs') || 45000);

function report(result) {
    window.potreeResult = result;
    document.title = 'done';
}

function yieldTask() {
    return new Promise((resolve) => {
        const channel = new MessageChannel();
        channel.port1.onmessage = resolve;
        channel.port2.postMessage(0);
    });
}

// Visits every node potree-core created from hierarchy.bin so far (proxies it has not expanded
// yet included, as they are in the tree).
function walk(node, visit) {
    if (!node) {
        return;
    }
    visit(node);
    for (const child of node.children || []) {
        walk(child, visit);
    }
}

async function main() {
    const canvas = document.getElementById('view');
    const renderer = new THREE.WebGLRenderer({canvas, antialias: false, preserveDrawingBuffer: true});
    renderer.setPixelRatio(1);
    renderer.setSize(width, height);
    renderer.setClearColor(0x000000, 1);
    const scene = new THREE.Scene();
    const camera = new THREE.PerspectiveCamera(45, width / height, 0.1, 1000);

    const potree = new Potree();
    potree.pointBudget = Infinity; // unlimited: every node in view is loaded
    potree.maxNumNodesLoading = 16;
    const started = performance.now();
    const pco = await potree.loadPointCloud('metadata.json', '/cloud/');
    pco.minNodePixelSize = 0; // no node is too small on screen to be loaded
    pco.pcoGeometry.maxNumNodesLoading = 16; // potree-core's own cap (3) besides Potree's
    // Fixed point sizes: the adaptive ones keep one texel per visible node in a 2048-texel
    // texture, and with no point budget and every node in view there are more.
    pco.material.pointSizeType = PointSizeType.FIXED;
    pco.material.size = 1.5;
    pco.material.inputColorEncoding = 1; // as potree-core's own example sets them
    pco.material.outputColorEncoding = 1;
    scene.add(pco);

    // Fit the camera to the cloud's points (metadata.json's position range): every node's box
    // holds some of them, so every node intersects the frustum.
    const metadata = await (await fetch('/cloud/metadata.json')).json();
    const position = metadata.attributes.find((attribute) => attribute.name === 'position');
    const box = new THREE.Box3(new THREE.Vector3(...position.min), new THREE.Vector3(...position.max));
    const sphere = box.getBoundingSphere(new THREE.Sphere());
    const fov = THREE.MathUtils.degToRad(camera.fov);
    const distance = sphere.radius / Math.sin(Math.min(fov, fov * camera.aspect) / 2);
    // From the front (-y), a little to the side and above, z up: as scans are stored.
    const towardsCamera = new THREE.Vector3(0.35, -1.0, 0.45).normalize();
    camera.position.copy(sphere.center).addScaledVector(towardsCamera, distance);
    camera.up.set(0, 0, 1);
    camera.near = distance / 1000;
    camera.far = distance * 4;
    camera.lookAt(sphere.center);
    camera.updateProjectionMatrix();
    camera.updateMatrixWorld(true);

    // Update until nothing is loading, nothing waits to load or to reach the GPU, and the
    // visible count holds still for a few updates in a row.
    let quiet = 0, last = -1, updates = 0, result;
    while (quiet < 5) {
        if (performance.now() - started > timeoutMs) {
            let unloaded = 0, failed = 0;
            walk(pco.pcoGeometry.root, (node) => {
                unloaded += node.loaded ? 0 : 1;
                failed += node.failed ? 1 : 0;
            });
            throw new Error(`loading did not settle within ${timeoutMs} ms: visible points ` +
                            `${last}, visible nodes ${pco.visibleNodes.length}, nodes loading ` +
                            `${pco.pcoGeometry.numNodesLoading}, waiting ` +
                            `${result.nodeLoadPromises.length}, unloaded ${unloaded}, failed ` +
                            `${failed}, updates ${updates}`);
        }
        result = potree.updatePointClouds([pco], camera, renderer);
        ++updates;
        const busy = pco.pcoGeometry.numNodesLoading > 0 || result.nodeLoadPromises.length > 0 ||
                     result.exceededMaxLoadsToGPU;
        if (result.nodeLoadFailed) {
            throw new Error('potree-core failed to load a node');
        }
        quiet = !busy && result.numVisiblePoints === last ? quiet + 1 : 0;
        last = result.numVisiblePoints;
        // A task boundary each update, so that fetch and worker replies get in (a loop of
        // microtasks only would starve them); a message port, not a timer, which clamps to 4 ms.
        await yieldTask();
    }
    renderer.render(scene, camera);

    let loadedPoints = 0;
    for (const node of pco.visibleNodes) {
        const position = node.geometryNode.geometry?.attributes?.position;
        loadedPoints += position ? position.count : 0;
    }
    let hierarchyNodes = 0, hierarchyPoints = 0;
    walk(pco.pcoGeometry.root, (node) => {
        ++hierarchyNodes;
        hierarchyPoints += node.numPoints;
    });

    // Pixels that are not the background: the screenshot shows the cloud, not an empty frame.
    const gl = renderer.getContext();
    const pixels = new Uint8Array(width * height * 4);
    gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    let litPixels = 0, distinctColors = new Set();
    for (let i = 0; i < pixels.length; i += 4) {
        if (pixels[i] + pixels[i + 1] + pixels[i + 2] > 0) {
            ++litPixels;
            distinctColors.add((pixels[i] << 16) | (pixels[i + 1] << 8) | pixels[i + 2]);
        }
    }
    report({
        ok: true,
        metadataPoints: metadata.points,
        numVisiblePoints: result.numVisiblePoints,
        loadedPoints,
        visibleNodes: pco.visibleNodes.length,
        hierarchyNodes,
        hierarchyPoints,
        updates,
        litPixels,
        totalPixels: width * height,
        seconds: (performance.now() - started) / 1000,
        webgl: renderer.capabilities.isWebGL2 ? 2 : 1,
        distinctColors: distinctColors.size,
    });
}

main().catch((error) => report({ok: false, error: String(error && error.stack || error)}));
