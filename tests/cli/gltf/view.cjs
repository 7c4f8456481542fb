// node view.cjs FILE.glb OUTDIR TIME: loads a glTF binary with three.js's
// GLTFLoader in headless Chromium (playwright-core driving the Debian
// chromium, software WebGL), renders it from the front at the animation's
// start and at TIME seconds, and saves both as OUTDIR/neutral.png and
// OUTDIR/played.png. Then it reads the two screenshots back and prints:
//   background P      the share of pixels, in percent, that differ from the
//                     background colour, per screenshot
//   changed P         the share of pixels that differ between the two
// It fails (exit 1) on any page error. The caller judges the numbers.
// Environment: NODE_PATH (the node_modules with playwright-core and three),
// AFM_CHROMIUM (default /usr/bin/chromium).
'use strict';
const fs = require('fs');
const path = require('path');
const { chromium } = require('playwright-core');

const [glb, outDir, timeArg] = process.argv.slice(2);
if (!glb || !outDir || timeArg === undefined) {
  console.error('usage: node view.cjs FILE.glb OUTDIR TIME');
  process.exit(2);
}
const three = path.dirname(path.dirname(require.resolve('three')));  // three/build/three.cjs
const origin = 'http://afm.invalid';  // never resolved: every request is answered below
const size = 320;
const background = [40, 60, 90];

const page_html = `<!doctype html><html><head><meta charset="utf-8">
<style>html,body{margin:0;background:#000}canvas{display:block}</style>
<script type="importmap">{"imports":{"three":"/three/build/three.module.js","three/addons/":"/three/examples/jsm/"}}</script>
</head><body><script type="module">
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.setSize(${size}, ${size});
document.body.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color().setRGB(${background.map((c) => c / 255).join(',')}, THREE.SRGBColorSpace);
scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 2.0));
const sun = new THREE.DirectionalLight(0xffffff, 2.0);
sun.position.set(0.3, 0.5, 1);
scene.add(sun);
window.afmLoad = async () => {
  const gltf = await new GLTFLoader().loadAsync('/model.glb');
  scene.add(gltf.scene);
  const box = new THREE.Box3().setFromObject(gltf.scene);
  const centre = box.getCenter(new THREE.Vector3()), extent = box.getSize(new THREE.Vector3());
  const camera = new THREE.PerspectiveCamera(25, 1, 0.001, 1000);
  const distance = 1.2 * Math.max(extent.x, extent.y) / (2 * Math.tan(THREE.MathUtils.degToRad(12.5)));
  camera.position.set(centre.x, centre.y, centre.z + extent.z / 2 + distance);
  camera.lookAt(centre);
  const mixer = new THREE.AnimationMixer(gltf.scene);
  if (gltf.animations.length) mixer.clipAction(gltf.animations[0]).play();
  window.afmShow = (t) => { mixer.setTime(t); renderer.render(scene, camera); };
  let targets = 0;
  gltf.scene.traverse((o) => { if (o.morphTargetDictionary) targets += Object.keys(o.morphTargetDictionary).length; });
  return { animations: gltf.animations.length, targets, duration: gltf.animations.length ? gltf.animations[0].duration : 0 };
};
// Pixels of a PNG (a data URL), through a 2D canvas.
async function pixels(url) {
  const img = new Image();
  img.src = url;
  await img.decode();
  const c = document.createElement('canvas');
  c.width = img.width, c.height = img.height;
  const g = c.getContext('2d');
  g.drawImage(img, 0, 0);
  return g.getImageData(0, 0, c.width, c.height).data;
}
const differs = (a, i, b, j) => Math.abs(a[i] - b[j]) + Math.abs(a[i + 1] - b[j + 1]) + Math.abs(a[i + 2] - b[j + 2]) > 12;
window.afmCompare = async (urlA, urlB, bg) => {
  const a = await pixels(urlA), b = await pixels(urlB);
  const n = a.length / 4;
  let fa = 0, fb = 0, changed = 0;
  for (let i = 0; i < a.length; i += 4) {
    if (differs(a, i, bg, 0)) ++fa;
    if (differs(b, i, bg, 0)) ++fb;
    if (differs(a, i, b, i)) ++changed;
  }
  return { n, foregroundA: 100 * fa / n, foregroundB: 100 * fb / n, changed: 100 * changed / n };
};
window.afmReady = true;
</script></body></html>`;

function contentType(file) {
  if (file.endsWith('.js')) return 'text/javascript';
  if (file.endsWith('.glb')) return 'model/gltf-binary';
  return 'text/html';
}

(async () => {
  const browser = await chromium.launch({
    executablePath: process.env.AFM_CHROMIUM || '/usr/bin/chromium',
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--no-sandbox'],
  });
  let failed = false;
  try {
    const page = await browser.newPage({ viewport: { width: size, height: size } });
    page.on('pageerror', (e) => {
      console.error('page error: ' + e.message);
      failed = true;
    });
    page.on('console', (m) => {
      if (m.type() === 'error') {
        console.error('page console: ' + m.text());
        failed = true;
      }
    });
    await page.route(origin + '/**', async (route) => {
      const url = new URL(route.request().url());
      let file = null;
      if (url.pathname === '/') return route.fulfill({ body: page_html, contentType: 'text/html' });
      if (url.pathname === '/model.glb') file = glb;
      else if (url.pathname.startsWith('/three/')) file = path.join(three, url.pathname.slice('/three/'.length));
      if (!file || !fs.existsSync(file)) return route.fulfill({ status: 404, body: 'not found' });
      return route.fulfill({ body: fs.readFileSync(file), contentType: contentType(file) });
    });
    await page.goto(origin + '/');
    await page.waitForFunction(() => window.afmReady === true, null, { timeout: 30000 });
    const info = await page.evaluate(() => window.afmLoad());
    console.log(`loaded: ${info.animations} animation(s), ${info.targets} morph targets, ${info.duration} s`);
    const shots = [];
    for (const [name, t] of [['neutral', 0], ['played', Number(timeArg)]]) {
      await page.evaluate((time) => window.afmShow(time), t);
      const png = await page.screenshot({ path: path.join(outDir, name + '.png') });
      shots.push('data:image/png;base64,' + png.toString('base64'));
    }
    const r = await page.evaluate(([a, b, bg]) => window.afmCompare(a, b, bg), [shots[0], shots[1], background]);
    console.log(`neutral: ${r.foregroundA.toFixed(2)} % not background`);
    console.log(`played: ${r.foregroundB.toFixed(2)} % not background`);
    console.log(`changed: ${r.changed.toFixed(2)} %`);
  } catch (e) {
    console.error('view failed: ' + (e && e.stack ? e.stack : e));
    failed = true;
  } finally {
    await browser.close();
  }
  process.exit(failed ? 1 : 0);
})();
