// Shared helpers for six.mjs and lod.mjs: load the npm packages installed in the tool
// directory (GLTF_TOOLS, see make.sh) and rewrite the JSON chunk of a GLB file.
import { copyFileSync, readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';

/** Imports the ES module entry point of package `name` from `${toolDir}/node_modules`. */
export async function load(toolDir, name) {
	const dir = join(toolDir, 'node_modules', name);
	const pkg = JSON.parse(readFileSync(join(dir, 'package.json'), 'utf8'));
	let entry = pkg.exports ? (pkg.exports['.'] ?? pkg.exports) : pkg.module ?? pkg.main;
	while (entry && typeof entry === 'object') entry = entry.import ?? entry.default;
	if (typeof entry !== 'string') throw new Error(`no ES entry point in ${name}`);
	return import(pathToFileURL(join(dir, entry)).href);
}

/** Splits a GLB into its JSON object and the raw BIN chunk (or null). */
export function readGlb(path) {
	const b = readFileSync(path);
	if (b.readUInt32LE(0) !== 0x46546c67 || b.readUInt32LE(4) !== 2) throw new Error(`${path}: not GLB 2`);
	let off = 12, json = null, bin = null;
	while (off < b.length) {
		const len = b.readUInt32LE(off), type = b.readUInt32LE(off + 4);
		const data = b.subarray(off + 8, off + 8 + len);
		if (type === 0x4e4f534a) json = JSON.parse(data.toString('utf8'));
		else if (type === 0x004e4942) bin = data;
		off += 8 + len;
	}
	return { json, bin };
}

/** Writes a GLB from a JSON object and an optional BIN chunk (both padded to 4 bytes). */
export function writeGlb(path, json, bin) {
	let j = Buffer.from(JSON.stringify(json), 'utf8');
	j = Buffer.concat([j, Buffer.alloc((4 - (j.length % 4)) % 4, 0x20)]);
	const parts = [chunk(j, 0x4e4f534a)];
	if (bin) parts.push(chunk(Buffer.concat([bin, Buffer.alloc((4 - (bin.length % 4)) % 4, 0)]), 0x004e4942));
	const body = Buffer.concat(parts);
	const head = Buffer.alloc(12);
	head.writeUInt32LE(0x46546c67, 0);
	head.writeUInt32LE(2, 4);
	head.writeUInt32LE(12 + body.length, 8);
	writeFileSync(path, Buffer.concat([head, body]));
}

function chunk(data, type) {
	const h = Buffer.alloc(8);
	h.writeUInt32LE(data.length, 0);
	h.writeUInt32LE(type, 4);
	return Buffer.concat([h, data]);
}

/**
 * Reads `src`, lets `edit` change its JSON in place, writes the result to `dst`; BIN is kept as is.
 * If `edit` changed nothing, `dst` is a byte copy of `src`.
 */
export function editGlb(src, dst, edit) {
	const { json, bin } = readGlb(src);
	const before = JSON.stringify(json);
	edit(json);
	if (JSON.stringify(json) === before) copyFileSync(src, dst);
	else writeGlb(dst, json, bin);
}
