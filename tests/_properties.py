"""Helpers of the property tests: what may escape a public function, and how it must read."""


def raises_naming(exc, *names, allowed=(ValueError, TypeError)):
    """The exception is one of ``allowed``, one line, and names one of ``names``."""
    assert isinstance(exc, allowed), f"{type(exc).__name__} escaped: {exc}"
    msg = str(exc)
    assert "\n" not in msg.strip(), f"not one line: {msg!r}"
    assert any(n in msg for n in names), f"message {msg!r} names none of {names}"


def call(fn, *names, allowed=(ValueError, TypeError)):
    """fn() or None when it raised an allowed exception naming one of ``names``."""
    try:
        return fn()
    except Exception as exc:  # noqa: BLE001 - the property is about what escapes
        raises_naming(exc, *names, allowed=allowed)
        return None
