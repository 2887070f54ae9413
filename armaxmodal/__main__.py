from armaxmodal.cli.main import run

run()
