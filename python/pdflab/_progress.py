"""The progress of a long call: a bar that updates in place in a notebook (an
output area of its own), or a line redrawn on a terminal as the command line
draws it. A call that ends within half a second shows nothing."""

import html
import sys
import time

# A bar appears only for a call still running after this long.
_SHOW_AFTER = 0.5
_WIDTH = 32


def _in_notebook():
    # A kernel has imported IPython long before; importing it here would cost
    # a plain script half a second.
    ipython = sys.modules.get("IPython")
    if ipython is None:
        return False
    shell = ipython.get_ipython()
    # A Jupyter kernel (a notebook, nbconvert --execute), not a terminal IPython.
    return shell is not None and type(shell).__name__ == "ZMQInteractiveShell"


class _Bar:
    """One state of the bar, as HTML for a notebook and as text elsewhere."""

    def __init__(self, label, fraction, text):
        self.label, self.fraction, self.text = label, max(0.0, min(1.0, fraction)), text

    def __repr__(self):
        filled = int(self.fraction * _WIDTH)
        return "%s [%s%s] %3d%%  %s" % (self.label, "#" * filled, "." * (_WIDTH - filled), int(self.fraction * 100),
                                        self.text)

    def _repr_html_(self):
        return ('<div style="font-family: monospace">%s <progress value="%.3f" max="1" style="width: 16em">'
                '</progress> %3d%%&nbsp; %s</div>' % (html.escape(self.label), self.fraction,
                                                       int(self.fraction * 100), html.escape(self.text)))


class Progress:
    """progress=None: shown in a notebook or on a terminal; True: always (on stderr off a notebook); False: never."""

    def __init__(self, label, enabled):
        self.label = label
        self.mode = None
        if enabled is None or enabled:
            if _in_notebook():
                self.mode = "notebook"
            elif enabled or sys.stderr.isatty():
                self.mode = "terminal"
        self.shown = self.mode is not None
        self._start = time.monotonic()
        self._handle = None
        self._drawn = False

    def update(self, status):
        if not self.shown or time.monotonic() - self._start < _SHOW_AFTER:
            return
        self._draw(_Bar(self.label, *status))

    def close(self, status):
        """The final state, where a bar was shown."""
        if self._drawn:
            self._draw(_Bar(self.label, *status))
            if self.mode == "terminal":
                sys.stderr.write("\n")
                sys.stderr.flush()

    def _draw(self, bar):
        if self.mode == "notebook":
            from IPython.display import display
            if self._handle is None:
                self._handle = display(bar, display_id=True)
            else:
                self._handle.update(bar)
        else:
            sys.stderr.write("\r%r " % (bar,))
            sys.stderr.flush()
        self._drawn = True
