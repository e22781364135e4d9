#!/usr/bin/env python3
"""Counts the library's public items from rustdoc's JSON (nightly): the items a user of the
crate can name, by kind, as the pages show them and with the modules hidden from the pages.

    scripts/public_surface.py            # builds the JSON twice (needs `rustup toolchain install nightly`)
    scripts/public_surface.py FILE.json  # counts one JSON already built

The JSON lists each item reachable from the crate's root under `paths` (crate 0), once, at
the path rustdoc shows it; `items on two paths or more` walks the modules and their public
`use`s from the root and counts the items a user can name in more than one way.
"""
import collections, json, os, subprocess, sys

KINDS = ('function', 'struct', 'enum', 'trait', 'constant', 'static', 'type_alias', 'macro', 'module')


def count(path):
    doc = json.load(open(path))
    kinds = collections.Counter(p['kind'] for p in doc['paths'].values() if p['crate_id'] == 0)
    # methods and associated items of public types: the index's items of the local crate
    methods = sum(1 for i in doc['index'].values()
                  if i.get('crate_id') == 0 and i['visibility'] == 'public'
                  and 'function' in i['inner'] and str(i['id']) not in doc['paths'])
    row = {k: kinds.get(k, 0) for k in KINDS}
    row['items on two paths or more'] = sum(1 for v in reachable_paths(doc).values() if len(v) > 1)
    row['items'] = sum(kinds.get(k, 0) for k in KINDS if k != 'module')
    row['public methods'] = methods
    return row


def reachable_paths(doc):
    """Every public path of each local item, found by walking the modules from the root and
    following public `use`s (a re-exported module is walked at its new path too)."""
    index = doc['index']
    found = collections.defaultdict(set)

    def walk(module_id, path, seen):
        if module_id in seen:
            return
        seen = seen | {module_id}
        for child in index[str(module_id)]['inner']['module']['items']:
            item = index.get(str(child))
            if item is None or item.get('crate_id') != 0 or item['visibility'] != 'public':
                continue
            inner = item['inner']
            if 'use' in inner:
                use = inner['use']
                target = index.get(str(use.get('id')))
                if use.get('is_glob') or target is None or target.get('crate_id') != 0:
                    continue
                if 'module' in target['inner']:
                    walk(target['id'], path + (use['name'],), seen)
                else:
                    found[target['id']].add(path + (use['name'],))
            elif 'module' in inner:
                walk(item['id'], path + (item['name'],), seen)
            elif item['name']:
                found[item['id']].add(path + (item['name'],))

    walk(doc['root'], ('penumbra',), frozenset())
    return found


def build(extra):
    target = os.environ.get('CARGO_TARGET_DIR', 'target')
    subprocess.run(['cargo', '+nightly', 'rustdoc', '--lib', '--', '-Z', 'unstable-options',
                    '--output-format', 'json', *extra], check=True)
    return os.path.join(target, 'doc', 'penumbra.json')


if __name__ == '__main__':
    if len(sys.argv) > 1:
        for f in sys.argv[1:]:
            print(f, json.dumps(count(f)))
    else:
        shown = count(build([]))
        hidden = count(build(['--document-hidden-items']))
        print('as the pages show it:', json.dumps(shown))
        print('with hidden modules: ', json.dumps(hidden))
