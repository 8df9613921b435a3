"""The DDA state of a scene as text for ``O.tags``: the codec of yade_dda.saveload.

The tag holds ``"<FORMAT> <base64 of zlib of (u64 info length, info JSON, core
state)>"``; the core state is ``_core.Scene.saveState``'s versioned,
checksummed binary. ``scene.restoreState`` rebuilds a scene from it.
"""
import base64
import binascii
import json
import struct
import zlib

from ._yade import O

STATE_TAG = 'yade_dda.state'
# Text format of the tag: "<FORMAT> <base64 of zlib of (u64 info length, info JSON, core state)>".
FORMAT = 'yade_dda-state/1'


def tag(name):
    """O.tags[name], or '' when absent (YADE's tags have no get or del)."""
    return O.tags[name] if name in O.tags.keys() else ''


def encodeState(scene):
    """The tag text holding a DDA scene's full state (see the module docstring)."""
    info = dict(token=scene.token, iter=O.iter, steps=scene.core.steps(), bodies=scene.bodyOfBlock,
                cover=list(scene.cover) if scene.cover is not None else None,
                checked=scene.overlapsChecked)
    infoBytes = json.dumps(info, separators=(',', ':')).encode('utf-8')
    raw = struct.pack('<Q', len(infoBytes)) + infoBytes + scene.core.saveState()
    return FORMAT + ' ' + base64.b64encode(zlib.compress(raw, 1)).decode('ascii')


def decodeState(text):
    """(info dict, core state bytes) from a tag text; ValueError naming what is wrong."""
    where = "O.tags['%s']" % STATE_TAG
    head, _, body = text.partition(' ')
    if not head.startswith('yade_dda-state/'):
        raise ValueError('%s does not hold a yade_dda state (it starts with %r)' % (where, text[:20]))
    if head != FORMAT:
        raise ValueError('%s has format %s; this yade_dda reads %s' % (where, head, FORMAT))
    try:
        compressed = base64.b64decode(body.encode('ascii'), validate=True)
    except (binascii.Error, UnicodeEncodeError, ValueError) as error:
        raise ValueError('%s is truncated or corrupt: not base64 (%s)' % (where, error)) from None
    try:
        raw = zlib.decompress(compressed)
    except zlib.error as error:
        raise ValueError('%s is truncated or corrupt: zlib says %s' % (where, error)) from None
    if len(raw) < 8:
        raise ValueError('%s is truncated: %d bytes' % (where, len(raw)))
    (n,) = struct.unpack('<Q', raw[:8])
    try:
        info = json.loads(raw[8:8 + n].decode('utf-8'))
        if not isinstance(info, dict) or not {'token', 'iter', 'steps', 'bodies'} <= set(info):
            raise ValueError('keys missing')
    except ValueError as error:
        raise ValueError('%s is corrupt: its header cannot be read (%s)' % (where, error)) from None
    return info, raw[8 + n:]
