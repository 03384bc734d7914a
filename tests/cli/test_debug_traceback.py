"""``--debug`` shows the traceback of an OSError however early it comes: without it, one line."""
from __future__ import annotations

import pytest

import pipelines.cli.app
import pipelines.cli.eval_cmd
from pipelines.cli import main


@pytest.mark.parametrize("where", ["building", "loading", "parsing"])
def test_debug_shows_the_traceback_of_an_oserror_before_the_arguments_are_parsed(
        where: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """An unreadable module while the parser is built or the chosen command's module loads, or a
    folder option that cannot be looked at (EACCES on the way to it), was a one-line error even
    with --debug."""
    def denied(*args: object, **kwargs: object) -> None:
        raise PermissionError(13, "Permission denied", "/opt/somewhere")

    if where == "building":
        monkeypatch.setattr(pipelines.cli.app, "build_parser", denied)
    elif where == "loading":
        monkeypatch.setattr(pipelines.cli.app.importlib, "import_module", denied)
    else:
        monkeypatch.setattr(pipelines.cli.eval_cmd, "existing_dir", denied)
    args = ["eval", "samples/demo.mp4", "--model-dir", "/opt/somewhere"]
    assert main(args) == 1
    assert capsys.readouterr().err.endswith("error: [Errno 13] Permission denied: '/opt/somewhere'\n")
    with pytest.raises(PermissionError):
        main([*args, "--debug"])
