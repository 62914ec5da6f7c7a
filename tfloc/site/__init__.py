"""``tfloc site``: a static site of leaderboards written from the run directories, opened from
disk with no server and no network, and the README's and docs' generated blocks from the same
rows. ``pages.toml`` maps each page to its run directories; :mod:`.collect` reads the results
root; :mod:`.board`, :mod:`.cost` and :mod:`.advice` build the tables and statements;
:mod:`.html`, :mod:`.runpage` and :mod:`.markdown` render them; :mod:`.build` writes the files."""
